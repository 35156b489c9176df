"""Sphinx configuration of the eulerpoisson documentation (``make docs``)."""

from __future__ import annotations

import importlib.util
import os
import sys
from pathlib import Path

DOCS = Path(__file__).resolve().parent
sys.path.insert(0, str(DOCS / "_ext"))
os.environ.setdefault("MPLBACKEND", "Agg")

import ep_docs  # noqa: E402

import eulerpoisson  # noqa: E402

project = "eulerpoisson"
author = "eulerpoisson developers"
copyright = "eulerpoisson developers"
release = eulerpoisson.__version__
version = release

extensions = [
    "ep_cli",  # the command-line reference, generated from the parser (.. eulerpoisson-cli::)
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "myst_parser",
]
# MathJax copied into the site (the docs extra installs it), so the formulas render offline too; without
# the package the pages load MathJax from its CDN
if importlib.util.find_spec("sphinx-mathjax-offline") is not None:
    extensions.append("sphinx-mathjax-offline")

# smart quotes without "--" -> en dash: a flag written outside a literal (--quaternion-order) stays
# a flag that can be copied and pasted
smartquotes_action = "qe"
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_ext", "_templates", "**/GALLERY_HEADER.rst"]
exclude_patterns += ["auto_examples/*.ipynb", "auto_examples/*.py", "auto_examples/*.zip"]
templates_path = ["_templates"]
nitpicky = True
# references that cannot resolve without intersphinx (the build needs no network): other libraries, the
# standard library; and the package's implementation modules, which the API reference does not list
_OTHERS = (
    r"(numpy|np|scipy|matplotlib|mpl_toolkits|xarray|h5netcdf|h5py|netCDF4|zarr|dask|distributed|"
    r"sympy|mpmath|numba|rich|heyoka|mujoco|os|pathlib|typing|collections|dataclasses|fractions|"
    r"multiprocessing|concurrent|argparse|json|tomllib|io|threading)(\..*)?"
)
nitpick_ignore_regex = [(r"py:.*", _OTHERS)]
nitpick_ignore = [("py:mod", name) for name in sorted(ep_docs.internal_modules())]

# --- API: autodoc, autosummary, numpydoc ------------------------------------------------------------
API_MODULES = ep_docs.api_modules()
ep_docs.write_api_pages(API_MODULES, DOCS)

autosummary_generate = True
autosummary_generate_overwrite = True
# names exported by two modules are documented where they appear first, the other page says "alias of"
autosummary_context = {"ep_aliases": ep_docs.aliases(API_MODULES)}
ep_docs.ALIASES = autosummary_context["ep_aliases"]
ep_docs.HOMES = ep_docs.homes(API_MODULES, ep_docs.ALIASES)
autodoc_typehints = "none"  # the numpydoc sections give the types; annotations would be cross-references
autodoc_default_options = {"member-order": "bysource"}
autodoc_inherit_docstrings = False

# numpydoc: the members of a class are documented by autodoc (``:members:`` in the class template), not
# listed again by numpydoc in tables that would need a stub page of their own for every method
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_show_inherited_class_members = False
numpydoc_xref_param_type = False
numpydoc_attributes_as_param_list = True
numpydoc_validation_checks: set = set()

# --- gallery --------------------------------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": "../examples",
    "gallery_dirs": "auto_examples",
    # every example runs, except those whose optional peer (MuJoCo) is not installed: shown, not run
    "filename_pattern": ep_docs.executable_pattern(),
    "ignore_pattern": r"__init__\.py",
    # the examples write their figures into the folder given as their argument; those files are the figures
    "reset_argv": "ep_docs.reset_argv",
    "image_scrapers": ("ep_docs.file_scraper",),
    "reset_modules": ("matplotlib", "ep_docs.close_figures"),
    "within_subsection_order": "FileNameSortKey",
    "remove_config_comments": True,
    "download_all_examples": False,
    "min_reported_time": 1,
    "write_computation_times": False,
}

# --- the audit report ----------------------------------------------------------------------------------


def _audit(app):
    run = bool(int(app.config.eulerpoisson_run_audit))
    seconds = ep_docs.write_audit_page(run, Path(app.srcdir))
    if run:
        print(f"eulerpoisson: audit report generated in {seconds:.1f} s")


def setup(app):
    app.add_config_value("eulerpoisson_run_audit", 1, "env", types=(int, bool, str))
    app.connect("builder-inited", _audit)
    app.connect("missing-reference", ep_docs.resolve_unqualified)
    app.connect("autodoc-process-docstring", ep_docs.data_docstring, priority=100)  # before numpydoc


# --- MyST (the benchmark summary, the audit report) ---------------------------------------------------
myst_enable_extensions = ["dollarmath", "amsmath"]
myst_heading_anchors = 3

# --- HTML -------------------------------------------------------------------------------------------------
html_theme = "pydata_sphinx_theme"
html_title = f"eulerpoisson {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version", "theme-version"],
}
html_static_path: list = []
html_show_sourcelink = False
