"""docs/design.md's "Repository layout" names every module of the packages, and only
modules that exist.

Pure file reading (no Taichi): the layout section is the text from its heading to the
next level-2 heading; a module is any back-quoted path ``pkg/.../name.py`` in it,
written from the repository root.
"""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DESIGN = ROOT / "docs" / "design.md"
PACKAGES = ("tdem", "physics", "coupling", "cases")

_HEADING = "## Repository layout"
_MODULE = re.compile(r"`((?:%s)/[A-Za-z0-9_/]*\.py)`" % "|".join(PACKAGES))


def _layout_section():
    text = DESIGN.read_text(encoding="utf-8")
    assert _HEADING in text, f"{DESIGN.relative_to(ROOT)} has no '{_HEADING}' section"
    section = text.split(_HEADING, 1)[1]
    nxt = re.search(r"^## ", section, flags=re.M)
    return section[: nxt.start()] if nxt else section


def _named_modules():
    return set(_MODULE.findall(_layout_section()))


def _tree_modules():
    found = set()
    for pkg in PACKAGES:
        for path in (ROOT / pkg).rglob("*.py"):
            rel = path.relative_to(ROOT)
            if "__pycache__" in rel.parts:
                continue
            found.add(rel.as_posix())
    return found


def test_layout_section_names_modules():
    assert _named_modules(), "the layout section of docs/design.md names no module"


def test_every_module_is_in_design_layout():
    missing = sorted(_tree_modules() - _named_modules())
    assert not missing, (
        "modules missing from the 'Repository layout' of docs/design.md "
        "(add a line for each): " + ", ".join(missing))


def test_every_module_in_design_layout_exists():
    extra = sorted(_named_modules() - _tree_modules())
    assert not extra, (
        "the 'Repository layout' of docs/design.md names modules that do not exist "
        "(renamed or removed?): " + ", ".join(extra))
