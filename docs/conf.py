"""Sphinx configuration of hystkit's documentation site (issue 30).

Build it, warnings as errors, from the repository's root (``pip install ".[docs]"`` first)::

    python -m sphinx -W --keep-going -b html docs docs/_build/html

The Markdown pages of ``docs/`` are pages of the site as they are (myst-parser). The API
reference is generated from the packages' ``__all__`` and numpydoc docstrings
(``_ext/hystkit_api.py`` + autosummary), the CLI reference from hystkit's argument parser
(``_ext/hystkit_cli.py``); neither is written by hand. The tutorial (``tutorial_src/``) and
the gallery (``examples/``) are run by sphinx-gallery when the site is built, their output and
figures on the page (generated into ``tutorial/`` and ``gallery/``, not in git).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))

import hystkit

project = "hystkit"
author = "the hystkit developers"
copyright = "the hystkit developers, MIT licence"
release = version = hystkit.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "hystkit_api",
    "hystkit_cli",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
templates_path = ["_templates"]
exclude_patterns = ["_build", "_templates", "_ext", "_scripts", "Thumbs.db", ".DS_Store",
                    "tutorial_src", "tutorial/*.ipynb", "gallery/*.ipynb"]

# Broken references are errors (with -W): every cross-reference must resolve.
nitpicky = True

# "--" stays "--" (options in help texts and prose, as GitHub shows the pages); quotes and
# ellipses are still typeset.
smartquotes_action = "qe"

# --- Markdown (the existing pages, unchanged) ---
myst_heading_anchors = 3  # the pages link to each other's sections by GitHub-style anchors

# --- API reference ---
autosummary_generate = True
autosummary_generate_overwrite = True
autosummary_imported_members = True  # the packages export what their private modules define
autodoc_typehints = "none"  # the numpydoc sections give every type, with shape and unit
autodoc_use_type_comments = False  # hystkit has no type comments; looking for them parses sources
autodoc_member_order = "bysource"
autodoc_default_options = {"exclude-members": "__init__, __new__"}
numpydoc_show_class_members = False  # the class template documents the members itself
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False  # types are prose ("array of float, shape (n,)")
numpydoc_validation_checks: set[str] = set()  # tests/docs/test_numpydoc.py validates them

# --- Tutorial and gallery (sphinx-gallery) ---
# Run at build time: the tutorial, the plot_* examples (seconds each) and the piezo example on
# its shipped excerpts. The others are shown as code; each says at its top why: centring_evidence
# (~50 s of fits on 2 cores) and every_family_in_the_loop (~60 s) would double the build, and
# boucwen_benchmark needs the shared Bouc-Wen data and h5py, which CI lacks.
sphinx_gallery_conf = {
    "examples_dirs": ["tutorial_src", "../examples"],
    "gallery_dirs": ["tutorial", "gallery"],
    "filename_pattern": r"(/plot_|/piezo_micromanipulator\.py$)",
    "reset_argv": "hystkit_gallery.reset_argv",
    "abort_on_example_error": True,  # an example that raises fails the build
    "remove_config_comments": True,
    "download_all_examples": False,
    "show_signature": False,
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "within_subsection_order": "FileNameSortKey",
}

# --- HTML ---
html_theme = "pydata_sphinx_theme"
html_title = f"hystkit {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
# An object's page (588 of the site's 670) has no left sidebar: its breadcrumbs lead to its
# package's page, which lists the package's objects. The sidebar there was the whole reference
# tree, ~80 kB of every such page: the site weighs 24 MB instead of 69, and builds in 35-37 s
# instead of 43-45 (2026-11-29, two alternating builds each).
html_sidebars = {"reference/api/generated/*": []}
html_show_sourcelink = False
html_copy_source = False  # no page links its source (above); the search reads the pages
