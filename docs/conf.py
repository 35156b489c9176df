"""Sphinx configuration of the eulerpoisson documentation (``make docs``)."""

from __future__ import annotations

import importlib.util
import os
import posixpath
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
    app.connect("html-page-context", _api_name_sidebar, priority=900)  # after the theme's (500)
    app.add_search_language(_english_search_memoized())


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


# --- build time ------------------------------------------------------------------------------------------
# Two shortcuts, through Sphinx's events and registry, that leave every page as it was (the same HTML, but for
# the left sidebar of the pages of one name, below): on 2 cores, the site's build (as tests/test_docs_site.py
# builds it) 44 -> ~37 s of CPU.


def _api_name_sidebar(app, pagename, templatename, context, doctree):
    """The left sidebar of the API's pages of one name (``api/generated/``): the list of the module pages.

    The theme's sidebar there listed every page of the API (the module pages and the ~300 pages of one name)
    and was resolved and serialized again for each of those ~300 pages (about 6 s of CPU). There it lists
    the module pages only (``maxdepth=1``: a module's page lists its names; the breadcrumbs above the page
    name its module): a list made once, and marked for each page at its module's entry as the theme marks
    it (``current active``). Anything else (another theme version's markup) gets the theme's own sidebar.
    """
    if not pagename.startswith("api/generated/") or "generate_toctree_html" not in context:
        return
    theirs = context["generate_toctree_html"]
    if not hasattr(app, "_ep_parents"):
        app._ep_parents, app._ep_sidebars = {}, {}
        for parent, children in app.env.toctree_includes.items():
            for child in children:
                app._ep_parents.setdefault(child, []).append(parent)
    parents = app._ep_parents.get(pagename, [])

    def generate_toctree_html(kind, startdepth=1, show_nav_level=1, **kwargs):
        if kind != "sidebar" or len(parents) != 1:
            return theirs(kind, startdepth, show_nav_level, **kwargs)
        kwargs["maxdepth"] = 1
        href = app.builder.get_relative_uri(pagename, parents[0])
        plain = f'<li class="toctree-l1"><a class="reference internal" href="{href}">'
        marked = plain.replace('"toctree-l1"', '"toctree-l1 current active"')
        # the same links from every page of the folder
        key = (posixpath.dirname(pagename), startdepth, show_nav_level, tuple(sorted(kwargs.items())))
        if key not in app._ep_sidebars:
            html = str(theirs(kind, startdepth, show_nav_level, **kwargs))
            app._ep_sidebars[key] = html.replace(marked, plain) if html.count(marked) == 1 else None
        common = app._ep_sidebars[key]
        if common is None or common.count(plain) != 1:
            return theirs(kind, startdepth, show_nav_level, **kwargs)
        return common.replace(plain, marked)

    context["generate_toctree_html"] = generate_toctree_html


def _english_search_memoized():
    """Sphinx's English search language, each word stemmed once (the pure-Python Snowball stemmer, called
    for every word of every page: 35000 calls for 5500 words)."""
    from sphinx.search.en import SearchEnglish

    class SearchEnglishMemoized(SearchEnglish):
        def __init__(self, options):
            super().__init__(options)
            self._stems: dict[str, str] = {}

        def stem(self, word: str) -> str:
            stem = self._stems.get(word)
            if stem is None:
                stem = self._stems[word] = super().stem(word)
            return stem

    return SearchEnglishMemoized
