"""pytest plugin: import ltpcontrol with the python-control bridge enabled.

Used by ``tools/control_suite.py`` as ``-p ltp_bridge_plugin`` so that
python-control's own tests run with ltpcontrol's dispatchers installed.
"""

import ltpcontrol

ltpcontrol.interop.enable()


def pytest_report_header(config):
    return (f"ltpcontrol {ltpcontrol.__version__}: python-control bridge enabled "
            f"({len(ltpcontrol.interop.BRIDGED)} entry points)")


def pytest_sessionfinish(session, exitstatus):
    # the suite must not have switched the bridge off (e.g. by resetting defaults)
    if not ltpcontrol.interop.is_enabled():
        raise RuntimeError("the python-control bridge was disabled during the run")
