"""Layers that point one way: ``physics/`` and ``coupling/`` reach into ``tdem`` only
through ``tdem.core``, and ``tdem.core`` imports nothing above it.

Pure source reading (``ast``, no import, no Taichi): every import statement of every
module, those inside functions included, and every ``importlib.import_module`` /
``__import__`` call with a literal name.
"""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# What physics/ and coupling/ may still import from tdem outside tdem.core, as
# (file, module) pairs, each with its reason.
ALLOWED = {
    # The package's __init__ imports tdem before its own modules. tdem.core is a
    # subpackage of tdem, so importing it runs tdem/__init__.py, which loads the
    # engine, which imports physics and coupling in its own order: without this, a
    # script that imports physics (or coupling) first would have the engine ask for
    # a module of the package that is still half-loaded. Removing it needs a
    # tdem/__init__.py that loads the engine on first use instead of at import.
    ("physics/__init__.py", "tdem"),
    ("coupling/__init__.py", "tdem"),
}


def _modules(pkg):
    for path in sorted((ROOT / pkg).rglob("*.py")):
        if "__pycache__" not in path.parts:
            yield path.relative_to(ROOT).as_posix(), path


def _imports(path):
    """(line, absolute module name) of every import in the file; ``from a import b``
    gives ``a.b`` (b may be a module or a name in a: both are below a)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name
        elif isinstance(node, ast.ImportFrom):
            if node.level:                       # relative: inside its own package
                continue
            for alias in node.names:
                yield node.lineno, (node.module if alias.name == "*"
                                    else f"{node.module}.{alias.name}")
        elif isinstance(node, ast.Call):
            f = node.func
            name = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", None)
            if (name in ("import_module", "__import__") and node.args
                    and isinstance(node.args[0], ast.Constant)
                    and isinstance(node.args[0].value, str)):
                yield node.lineno, node.args[0].value


def _under(name, top):
    return name == top or name.startswith(top + ".")


def _offending(pkgs, allowed_top, forbidden_tops):
    """{(file, module): [lines]} of the imports of ``forbidden_tops`` that are not
    ``allowed_top`` or below."""
    found = {}
    for pkg in pkgs:
        for rel, path in _modules(pkg):
            for line, name in _imports(path):
                if any(_under(name, t) for t in forbidden_tops) and not _under(name, allowed_top):
                    found.setdefault((rel, name), []).append(line)
    return found


def test_physics_and_coupling_import_tdem_only_through_core():
    found = _offending(("physics", "coupling"), "tdem.core", ("tdem",))
    bad = sorted(f"{rel}:{line}: {name}" for (rel, name), lines in found.items()
                 if (rel, name) not in ALLOWED for line in lines)
    assert not bad, ("physics/ and coupling/ import from tdem only through tdem.core "
                     "(move the constant or helper to tdem/core/): " + "; ".join(bad))


def test_allowed_list_is_current():
    found = _offending(("physics", "coupling"), "tdem.core", ("tdem",))
    stale = sorted(f"{rel}: {name}" for rel, name in ALLOWED if (rel, name) not in found)
    assert not stale, "entries of ALLOWED no longer needed (remove them): " + "; ".join(stale)


def test_core_imports_nothing_above_it():
    found = _offending(("tdem/core",), "tdem.core", ("tdem", "physics", "coupling", "cases"))
    bad = sorted(f"{rel}:{line}: {name}" for (rel, name), lines in found.items()
                 for line in lines)
    assert not bad, "tdem/core imports only itself, Taichi and the standard library: " + \
        "; ".join(bad)


def test_core_relative_imports_stay_in_core():
    # ``from .. import x`` in tdem/core would reach the engine
    bad = []
    for rel, path in _modules("tdem/core"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.level > 1:
                bad.append(f"{rel}:{node.lineno}")
    assert not bad, "tdem/core reaches above itself: " + "; ".join(bad)
