"""Sphinx configuration: the documents in Markdown (MyST) and the reference pages from
the docstrings (autodoc). Built by ``tests/test_docs_build.py`` with warnings as errors:
``python -m sphinx -W -b html docs docs/_build``."""
import os
import sys

sys.path.insert(0, os.path.abspath(".."))

project = "tdem"
extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.napoleon"]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
# the archived runs (their own Markdown tables) and reference data are linked, not pages
exclude_patterns = ["_build", "validation/**", "reference/**"]
myst_heading_anchors = 3
# links from the documents to files beside them in the repository (README, benchmarks,
# the archived runs' tables) are not Sphinx pages: they stay plain links
suppress_warnings = ["myst.xref_missing", "myst.header"]
autodoc_member_order = "bysource"
autodoc_typehints = "none"
html_theme = "alabaster"
