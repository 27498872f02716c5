"""Sphinx configuration for the ltpcontrol documentation."""

import os
import sys

sys.path.insert(0, os.path.abspath('..'))

import ltpcontrol  # noqa: E402

project = 'ltpcontrol'
author = 'ltpcontrol developers'
copyright = '2026, ltpcontrol developers'
release = version = ltpcontrol.__version__

extensions = [
    'sphinx.ext.autodoc',
    'sphinx.ext.autosummary',
    'sphinx.ext.intersphinx',
    'sphinx.ext.mathjax',
    'numpydoc',
    'sphinx_gallery.gen_gallery',
]

autosummary_generate = True
autodoc_default_options = {'members': False}
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_validation_checks = set()
default_role = 'py:obj'
# every page resolves names in the ltpcontrol namespace
rst_prolog = '.. currentmodule:: ltpcontrol\n'

# Internal link check: every reference must resolve, so a misspelt or removed
# name fails the build.  Exempt are only single-backtick names that are
# documented parameters, returns or attributes (numpydoc's way of naming an
# argument), and, when the inventories of other projects are not loaded,
# references into those projects.
nitpicky = True


def _documented_names():
    import inspect
    from numpydoc.docscrape import ClassDoc, FunctionDoc

    sections = ('Parameters', 'Other Parameters', 'Returns', 'Yields', 'Attributes')
    names = set()
    for obj in (getattr(ltpcontrol, n) for n in ltpcontrol.__all__):
        members = [obj]
        if inspect.isclass(obj):
            members += [m for k, m in vars(obj).items()
                        if callable(m) and (not k.startswith('_') or k == '__call__')]
        for member in members:
            doc = ClassDoc(member, config={'show_class_members': False}) \
                if inspect.isclass(member) else FunctionDoc(member)
            for section in sections:
                for item in doc[section]:
                    for name in item.name.replace('*', '').split(','):
                        names.add(name.strip())
                        if section == 'Attributes':      # e.g. PeriodicOrbit.monodromy
                            names.add(f"{member.__name__}.{name.strip()}")
            try:
                names.update(inspect.signature(member).parameters)
            except (TypeError, ValueError):
                pass
    return {name for name in names if name and not hasattr(ltpcontrol, name)}


nitpick_ignore = [('py:obj', name) for name in sorted(_documented_names())]
nitpick_ignore_regex = [
    # python-control's configuration keys named in docstrings
    ('py:obj', r"config\.defaults\[.*"),
]

intersphinx_mapping = {
    'python': ('https://docs.python.org/3', None),
    'numpy': ('https://numpy.org/doc/stable', None),
    'scipy': ('https://docs.scipy.org/doc/scipy', None),
    'matplotlib': ('https://matplotlib.org/stable', None),
    'control': ('https://python-control.readthedocs.io/en/0.10.2', None),
}
# the documentation must build offline: never fetch inventories
intersphinx_disabled_reftypes = ['*']
intersphinx_timeout = 1
if os.environ.get('LTP_DOCS_ONLINE') != '1':
    intersphinx_mapping = {}
    _external = r'(control|numpy|scipy|matplotlib|ast|StateSpace|TransferFunction|' \
        r'NonlinearIOSystem|BitGenerator|SeedSequence|solve_ivp|input_output_response)'
    nitpick_ignore_regex += [(r'py:.*', _external + r'(\..*)?')]

# Gallery: every `plot_*.py` script is executed and its figures rendered.
# The long reproductions run their reduced version (LTP_EXAMPLES_QUICK=1)
# unless LTP_DOCS_FULL=1 asks for the full runs.
if os.environ.get('LTP_DOCS_FULL') != '1':
    os.environ['LTP_EXAMPLES_QUICK'] = '1'


def _gallery_skips_example_pngs():
    """Figures saved into the examples folder are not drawn during the build.

    The gallery scripts save their figures as PNG files beside themselves
    for readers who run them; the gallery draws every figure itself (its
    image scraper) and the build never uses those files.  Skipping them
    leaves the pages as they are and saves one drawing per saved figure.
    """
    from matplotlib.figure import Figure
    examples = os.path.abspath(os.path.join('..', 'examples'))
    savefig = Figure.savefig

    def gallery_savefig(self, fname, *args, **kwargs):
        if (isinstance(fname, (str, os.PathLike))
                and os.path.dirname(os.path.abspath(fname)) == examples):
            return None
        return savefig(self, fname, *args, **kwargs)
    Figure.savefig = gallery_savefig


_gallery_skips_example_pngs()
sphinx_gallery_conf = {
    'examples_dirs': '../examples',
    'gallery_dirs': 'auto_examples',
    'ignore_pattern': r'(^|/)(?!plot_)[^/]+\.py$',
    'filename_pattern': r'/plot_',
    'only_warn_on_example_error': False,
    'within_subsection_order': 'FileNameSortKey',
    'download_all_examples': False,
    'show_memory': False,
    'remove_config_comments': True,
}

templates_path = ['_templates']
exclude_patterns = ['_build', 'auto_examples/*.ipynb', 'auto_examples/*.py',
                    'auto_examples/*.zip', 'auto_examples/*.md5', 'sg_execution_times.rst']
html_theme = 'pydata_sphinx_theme'
html_title = 'ltpcontrol'
html_static_path = []
html_theme_options = {'navigation_with_keys': False}
suppress_warnings = ['config.cache']
