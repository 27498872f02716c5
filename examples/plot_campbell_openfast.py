r"""
Campbell diagram of a wind turbine from OpenFAST linearization files
====================================================================

A wind-turbine study linearizes the turbine at several operating points
(wind speed and rotor speed) and, at each, at 36 rotor azimuths: one
OpenFAST ``.lin`` file per azimuth, one folder per operating point.  This
script writes such a study for a 16-state isotropic turbine (tower
fore-aft and side-side, flap and edge of three blades; the model is in
``examples/rotor_models.py``), then builds its Campbell diagram with
`ltpcontrol.campbell_lin`: the blade states are grouped from their
descriptions, transformed to multi-blade coordinates, the Floquet modes of
every operating point computed (time-invariant to the files' precision,
so by ``eig``), tracked by mode shape and named from the degrees of freedom
that participate.  The diagram is drawn in Hz against the rotor speed in
rpm, with the damping in percent, and exported as a table.

The backward and forward whirl of the blade modes separate from the
collective mode by ∓Ω, the picture that the multi-blade transform makes
visible; the tower side-side mode couples with the edgewise whirl.
"""

import os
import pathlib
import tempfile

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import ltpcontrol as ltp  # noqa: E402
from rotor_models import write_turbine_study  # noqa: E402

QUICK = os.environ.get('LTP_EXAMPLES_QUICK') == '1'

# %%
# The study: six operating points (rotor speed from 6 to 12 rpm with the
# wind), 36 azimuths each.
winds = np.array([5.0, 6.5, 8.0, 9.5, 11.0, 12.5])
speeds = np.round(np.linspace(6.0, 12.0, len(winds)) * np.pi / 30, 4)   # rad/s
root = write_turbine_study(pathlib.Path(tempfile.mkdtemp()), speeds, winds)
print(f"{len(list(root.rglob('*.lin')))} files in {len(winds)} folders")

# %%
# The diagram, against the rotor speed.
cd = ltp.campbell_lin(root, method='floquet', x='rotor_speed')
print(cd)
print("tracks:", sorted({cd.labels[k] for k in range(16) if cd.damped_frequency[0, k] > 0}))
print(f"smallest MAC between neighbouring operating points: {cd.mac.min():.4f}")

# %%
# A table of frequencies (Hz) and damping (%), one row per operating point
# and mode; ``cd.to_dataframe()`` gives the same as a pandas DataFrame.
table = cd.table()
last = table['value'] == cd.values[-1]
print(f"at {cd.values[-1] * 30 / np.pi:.1f} rpm, {cd.wind_speed[-1]:.1f} m/s:")
for label, f, z in sorted(zip(table['label'][last], table['frequency_hz'][last],
                              table['damping_percent'][last]), key=lambda r: r[1]):
    print(f"  {label:20s} {f:7.4f} Hz {z:6.2f} %")
cd.to_csv(root / 'campbell.csv')

cplt = cd.plot(x='rpm', frequency_unit='Hz', damping='percent',
               title='16-state isotropic turbine')
cplt.figure.set_size_inches(7, 6)
cplt.figure.tight_layout()
if not QUICK:
    plt.show()
