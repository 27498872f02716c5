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
nitpicky = False

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

# Gallery: only `plot_*.py` scripts are gallery entries; the quick ones are
# executed during the build, the longer reproductions are rendered as code.
sphinx_gallery_conf = {
    'examples_dirs': '../examples',
    'gallery_dirs': 'auto_examples',
    'ignore_pattern': r'(^|/)(?!plot_)[^/]+\.py$',
    'filename_pattern': r'/plot_(mathieu_htf|hopper_htf|switching_mathieu|analysis)\.py$',
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
