"""Sphinx configuration: the documents in Markdown (MyST) and the reference pages from
the docstrings (autodoc). Built by ``tests/test_docs_build.py`` with warnings as errors:
``python -m sphinx -W -b html docs docs/_build``. Links between the documents are
checked (a missing page or heading anchor is an error)."""
import os
import sys

sys.path.insert(0, os.path.abspath(".."))

project = "tdem"
extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.napoleon"]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
# the reference data are files, not pages (the archived sweeps' tables are pages)
exclude_patterns = ["_build", "reference/**"]
myst_heading_anchors = 3
# (the archived sweeps' tables, pages of a hidden toctree, start without a title)
suppress_warnings = ["myst.header", "toc.no_title"]
autodoc_member_order = "bysource"
autodoc_typehints = "none"
html_theme = "alabaster"
