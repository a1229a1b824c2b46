"""Sphinx configuration of the unibuckle_fenicsx documentation (``make docs``)."""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))
sys.path.insert(0, str(HERE.parent))

# mpi4py first: the PyPI wheels of petsc4py and DOLFINx find the MPI library that
# mpi4py loads, and autodoc may import any module of the package first.
from mpi4py import MPI  # noqa: E402, F401

import unibuckle_fenicsx  # noqa: E402

project = "unibuckle_fenicsx"
author = "the unibuckle_fenicsx developers"
copyright = "2026, the unibuckle_fenicsx developers"
release = unibuckle_fenicsx.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "unibuckle_docs",  # docs/_ext: the generated CLI, schema and benchmark pages
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
exclude_patterns = ["_build", "_generated", "Thumbs.db", ".DS_Store"]
templates_path = ["_templates"]

myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

autosummary_generate = True
autosummary_imported_members = False
autodoc_member_order = "bysource"
# Classes and functions are not headings of the navigation: with them the furo sidebar of
# every page holds the whole API, and the build takes twice as long.
toc_object_entries = False
autodoc_typehints = "description"
autodoc_default_options = {"members": True, "show-inheritance": True}
napoleon_google_docstring = True
napoleon_numpy_docstring = False
napoleon_use_ivar = True

html_theme = "furo"
html_title = f"unibuckle_fenicsx {release}"
html_static_path: list[str] = []

# The figures live in the repository's figures/ (written by `make figures`).
html_extra_path: list[str] = []
