"""Sphinx configuration of the unibuckle_fenicsx documentation (``make docs``)."""

from __future__ import annotations

import sys
import tomllib
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))
sys.path.insert(0, str(HERE.parent))

# mpi4py first: the PyPI wheels of petsc4py and DOLFINx find the MPI library that
# mpi4py loads, and autodoc may import any module of the package first.
from mpi4py import MPI  # noqa: E402, F401

from unibuckle_docs import (  # noqa: E402
    MATHJAX_PATH,
    intersphinx_mapping,
    public_callables,
    quickstart_numbers,
)

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
    "sphinx.ext.intersphinx",
    "unibuckle_docs",  # docs/_ext: the generated CLI, schema and benchmark pages
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
exclude_patterns = ["_build", "_generated", "Thumbs.db", ".DS_Store"]
templates_path = ["_templates"]

myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist", "substitution"]
# Numbers quoted on several pages, from one source each: docs/numbers.toml (the test count,
# the make times) and the quickstart's stored output (figures/quickstart/, by make demo).
myst_substitutions = {
    **tomllib.loads((HERE / "numbers.toml").read_text()),
    **{f"qs_{key}": value for key, value in quickstart_numbers().items()},
}
myst_heading_anchors = 3

autosummary_generate = True
autosummary_imported_members = False
# The public names are documented once, on the API page (docs/reference/api.rst): the
# module pages leave them out (docs/_templates/autosummary/module.rst).
autosummary_context = {"public": public_callables()}
autodoc_member_order = "bysource"
# Classes and functions are not headings of the navigation: with them the furo sidebar of
# every page holds the whole API, and the build takes twice as long.
toc_object_entries = False
autodoc_typehints = "description"
autodoc_default_options = {"members": True, "show-inheritance": True}
napoleon_google_docstring = True
napoleon_numpy_docstring = False
napoleon_use_ivar = True

# MathJax from a local copy (docs/_ext/unibuckle_docs.py copies it into _static): the
# site renders its equations without a network.
mathjax_path = MATHJAX_PATH

# Links to DOLFINx, NumPy, petsc4py, Python, ... The build has no network: the inventories
# are written from a table of the objects the pages name (docs/_ext/unibuckle_docs.py,
# INVENTORIES); the links go to the projects' online documentation.
intersphinx_mapping = intersphinx_mapping()
# Types in docstrings as the package writes them (module aliases) resolve to full names;
# type hints keep their aliases, which the inventories list too.
_ALIASES = {
    "npt.NDArray": "numpy.typing.NDArray",
    "npt.ArrayLike": "numpy.typing.ArrayLike",
    "np.float64": "numpy.float64",
    "np.int64": "numpy.int64",
    "np.int32": "numpy.int32",
    "np.bool_": "numpy.bool",
    "PETSc.Mat": "petsc4py.PETSc.Mat",
    "PETSc.Vec": "petsc4py.PETSc.Vec",
    "MPI.Comm": "mpi4py.MPI.Comm",
    "Path": "pathlib.Path",
}
napoleon_type_aliases = _ALIASES
# msgspec's bounds in the schema's type hints (Annotated[float, Meta(gt=0)]) are
# rendered as words beside the type: they name no object.
# Private names (a leading underscore: a base class, a helper) are not documented.
nitpick_ignore_regex = [
    ("py:class", r"(gt|ge|lt|le|min_length|max_length)=.*"),
    ("py:(class|func|meth|attr|data)", r"(.*\.)?_\w+"),
    # A function's own type parameter (PEP 695: factor_at[A: LowRankAttempt]) names no object.
    ("py:class", r"A"),
]

html_theme = "furo"
html_title = f"unibuckle_fenicsx {release}"
html_static_path = ["_static"]
html_css_files = ["unibuckle.css"]

# The figures live in the repository's figures/ (written by `make figures`).
html_extra_path: list[str] = []
