"""docs/api.md against the code: every public name is documented, with each of its
parameters.

The public API is read from the code with ``inspect`` (importing tdem starts no
Taichi kernel, so this is fast):

- ``tdem.Simulation``: its constructor, and every public method and property
  (those of its base classes included);
- the handles ``Wall``, ``Mesh``, ``Primitive``, ``Block``, ``ParticleGroup``: every
  public method
  and property;
- the other classes of ``tdem.__all__`` (contact laws, materials, shapes, errors):
  the class, its constructor and its static and class methods (the alternative
  constructors, ``Polyhedron.cube``, ``JWL.tnt``, ...);
- the functions of ``tdem.__all__`` and every public function defined in the
  exported modules ``tdem.pack``, ``tdem.mesh``, ``tdem.surfaces``;
- the functions of other modules that api.md names as ``tdem.<module>.<name>``
  (``tdem.io.read_monitors``, ``tdem.paraview.render``, ...).

The rule. A name is documented where api.md mentions it in the form a script uses
(``sim.run``, ``wall.servo``, ``tdem.pack.random``, ``tdem.LinearContact``; a
handle's member may also be back-quoted bare in a paragraph that names the handle,
as "`Block` methods: `fix(...)`"). Its entry is its defining mention: a heading that
holds it, else a table row that starts with it, else its first mention followed by
``(``, else its first mention; the entry is the text from a heading or a code block to
the next heading, or the table row, or the paragraph or list item that holds the
mention. Every parameter of the signature (``self``, ``*args`` and ``**kwargs``
aside) must appear as a word inside code (back-quotes or a code block) of that
entry; and a default written in the documented signature (``name=value``, a Python
literal) must equal the code's. The Taichi functions of the contact laws (``force``,
``energy``, ``stiffness``) are documented once, as the hooks of ``tdem.ContactLaw``.
What is left out on purpose is in ``ALLOWED`` and ``INTERNAL_CONSTRUCTORS`` below.
"""

import ast
import importlib
import inspect
import re
from pathlib import Path

import pytest

import tdem

ROOT = Path(__file__).resolve().parent.parent
API = ROOT / "docs" / "api.md"

HANDLES = {"Wall": ("wall", "Wall"), "Mesh": ("mesh", "Mesh"),
           "Primitive": ("plane", "Primitive"),
           "Block": ("block", "Block"), "ParticleGroup": ("group", "ParticleGroup")}

# Deliberately left out of the reference, each with the reason. Names here are not
# checked at all.
ALLOWED = {
    # Rebuilds a law from a checkpoint's record (Simulation.load calls it).
    "ContactLaw.from_dict",
}
# Classes whose name is checked but not their constructor's parameters.
INTERNAL_CONSTRUCTORS = {
    # Handles are made by sim.add_wall / add_mesh / add_plane / add_cylinder /
    # add_block / add_particles, never constructed by a script.
    "Wall()", "Mesh()", "Primitive()", "Block()", "ParticleGroup()",
    # Errors are raised by tdem, not by scripts; api.md documents their attributes.
    "InputError()", "InstabilityError()", "CapacityError()",
}

# The Taichi functions every contact law defines (tdem.ContactLaw's hooks).
LAW_HOOKS = ("force", "energy", "stiffness")

_INF_LITERAL = re.compile(r"^-?inf$")


# --------------------------------------------------------------------------- api.md


class Doc:
    """api.md split into lines, with its headings, code blocks and entries."""

    def __init__(self, text):
        self.lines = text.split("\n")
        n = len(self.lines)
        self.fence_open = [None] * n       # the line of the ``` opening the block held
        self.heading = [False] * n
        start = None
        for i, line in enumerate(self.lines):
            if line.lstrip().startswith("```"):
                if start is None:
                    start = i
                    self.fence_open[i] = i
                else:
                    self.fence_open[i] = start
                    start = None
                continue
            if start is not None:
                self.fence_open[i] = start
            elif line.startswith("#"):
                self.heading[i] = True

    def _next_heading(self, i):
        for j in range(i + 1, len(self.lines)):
            if self.heading[j]:
                return j
        return len(self.lines)

    def _breaks(self, i):
        line = self.lines[i]
        return (not line.strip() or self.heading[i] or self.fence_open[i] is not None
                or line.startswith("|"))

    def entry(self, i):
        """(first, last + 1) lines of the entry that holds line i."""
        line = self.lines[i]
        if self.heading[i]:
            return i, self._next_heading(i)
        if self.fence_open[i] is not None:
            return self.fence_open[i], self._next_heading(i)
        if line.startswith("|"):
            return i, i + 1
        a = i
        while not line.lstrip().startswith("- ") and a > 0 and not self._breaks(a - 1):
            a -= 1
            line = self.lines[a]
        b = i + 1
        while (b < len(self.lines) and not self._breaks(b)
               and not self.lines[b].lstrip().startswith("- ")):
            b += 1
        return a, b

    def code(self, a, b):
        """The code of lines [a, b): code blocks whole, and back-quoted spans."""
        parts, prose = [], []
        for i in range(a, b):
            (parts if self.fence_open[i] is not None else prose).append(self.lines[i])
        parts += re.findall(r"`([^`]+)`", "\n".join(prose))
        return "\n".join(parts)

    def text(self, a, b):
        return "\n".join(self.lines[a:b])


DOC = Doc(API.read_text(encoding="utf-8"))


def _mentions(patterns):
    """[(line, column after the name, in the first cell of a table row)] of every
    mention; a pattern is a regex, or (regex, context): the regex counts only in an
    entry whose text matches the context."""
    found = []
    for i, line in enumerate(DOC.lines):
        for pat in patterns:
            rx, context = pat if isinstance(pat, tuple) else (pat, None)
            for m in re.finditer(rx, line):
                if context is not None and not re.search(context, DOC.text(*DOC.entry(i))):
                    continue
                cells = line.split("|")
                first_cell = line.startswith("|") and m.start() < len(cells[0]) + len(cells[1]) + 2
                found.append((i, m.end(), first_cell))
    return sorted(set(found))


def _defining(mentions):
    """The defining mention: in a heading, else starting a table row, else the first
    followed by '(', else the first."""
    for test in (lambda m: DOC.heading[m[0]], lambda m: m[2],
                 lambda m: DOC.lines[m[0]][m[1]:m[1] + 1] == "("):
        for m in mentions:
            if test(m):
                return m
    return mentions[0]


def _signature_args(line, col):
    """The top-level arguments of the documented call whose '(' is at (line, col),
    up to its ')' (or the end of the back-quoted span)."""
    text = "\n".join(DOC.lines[line:line + 8])
    if text[col:col + 1] != "(":
        return []
    depth, args, cur = 0, [], ""
    for ch in text[col:]:
        if ch == "`":
            break
        if ch in "([{":
            depth += 1
            if depth == 1:
                continue
        elif ch in ")]}":
            depth -= 1
            if depth == 0:
                args.append(cur)
                break
        elif ch == "," and depth == 1:
            args.append(cur)
            cur = ""
            continue
        cur += ch
    return [" ".join(a.split()) for a in args]


# --------------------------------------------------------------------------- the code


class Item:
    """A documented name: its label in reports, the patterns of its mentions and its
    parameters {name: default} (self, *args and **kwargs aside)."""

    def __init__(self, label, obj, patterns, params=True):
        self.label, self.patterns, self.params = label, patterns, {}
        if not params or label in INTERNAL_CONSTRUCTORS:
            return
        try:
            sig = inspect.signature(obj)
        except (TypeError, ValueError):      # builtins without a signature
            return
        for p in sig.parameters.values():
            if p.name != "self" and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
                self.params[p.name] = p.default


def _alt(names):
    return "(?:" + "|".join(re.escape(n) for n in names) + ")"


def _call_patterns(prefixes, name, bare=False):
    """Mentions of ``prefix.name`` (and of a bare ``name`` not after a dot)."""
    pats = [r"(?<![\w.])%s\.%s(?!\w)" % (_alt(prefixes), re.escape(name))]
    if bare:
        pats.append(r"(?<![\w.])%s(?=\()" % re.escape(name))
    return pats


def _public_members(cls):
    """{name: (kind, object)} of the public methods and properties of cls and its
    bases (object's aside)."""
    out = {}
    for klass in reversed(cls.__mro__[:-1]):
        for name, raw in vars(klass).items():
            if name.startswith("_"):
                continue
            if isinstance(raw, property):
                out[name] = ("property", raw)
            elif isinstance(raw, (staticmethod, classmethod)):
                out[name] = ("static", getattr(cls, name))
            elif inspect.isfunction(raw):
                out[name] = ("method", raw)
    return out


def _items():
    items = []
    sim_prefixes = ("sim", "tdem.Simulation", "Simulation")
    items.append(Item("Simulation()", tdem.Simulation.__init__,
                      [r"(?<![\w.])(?:tdem\.)?Simulation(?=\()"]))
    for name, (kind, obj) in sorted(_public_members(tdem.Simulation).items()):
        items.append(Item("Simulation." + name, obj, _call_patterns(sim_prefixes, name),
                          params=kind != "property"))

    for cname, aliases in HANDLES.items():
        cls = getattr(tdem, cname)
        items.append(Item(cname + "()", cls.__init__,
                          [r"(?<![\w.])(?:tdem\.)?%s(?!\w)" % cname]))
        for name, (kind, obj) in sorted(_public_members(cls).items()):
            pats = _call_patterns(aliases, name)
            pats.append((r"(?<=`)%s(?![\w])" % re.escape(name), r"`%s`" % cname))
            items.append(Item(cname + "." + name, obj, pats, params=kind != "property"))

    for name in tdem.__all__:
        obj = getattr(tdem, name)
        if name in HANDLES or name == "Simulation" or inspect.ismodule(obj):
            continue
        # (a keyword argument of the same name, ``grading=None``, is no mention)
        cname = r"(?<![\w.])(?:tdem\.)?%s(?![\w=])" % re.escape(name)
        if inspect.isclass(obj):
            items.append(Item(name + "()", obj, [cname]))
            for mname, (kind, m) in sorted(_public_members(obj).items()):
                if kind != "static" or mname not in vars(obj):
                    continue
                if issubclass(obj, tdem.ContactLaw) and mname in LAW_HOOKS:
                    # a law's Taichi functions: documented once, for every law, as
                    # the hooks of tdem.ContactLaw (``def force(q, u, ...)``)
                    pats = [r"(?<![\w.])%s(?=\()" % mname]
                else:
                    pats = _call_patterns((name, "tdem." + name), mname)
                    pats.append(r"(?<![\w.])\.%s(?=\()" % re.escape(mname))
                items.append(Item(name + "." + mname, m, pats))
        else:
            items.append(Item(name, obj, [cname]))

    seen = {id(getattr(tdem, n)) for n in tdem.__all__}
    for module in (tdem.pack, tdem.mesh, tdem.surfaces):
        short = module.__name__.split(".")[-1]
        for name, obj in sorted(vars(module).items()):
            if (name.startswith("_") or not inspect.isfunction(obj)
                    or obj.__module__ != module.__name__ or id(obj) in seen):
                continue
            items.append(Item("%s.%s" % (module.__name__, name), obj,
                              _call_patterns(("tdem." + short,), name, bare=True)))

    text = API.read_text(encoding="utf-8")
    for modname, name in sorted(set(re.findall(r"tdem\.(\w+)\.(\w+)", text))):
        if modname in ("pack", "mesh", "surfaces") or name.startswith("_"):
            continue
        try:
            module = importlib.import_module("tdem." + modname)
        except ImportError:                  # tdem.JWL.tnt and the like: not a module
            continue
        obj = getattr(module, name, None)
        if inspect.isfunction(obj) and id(obj) not in seen:
            items.append(Item("tdem.%s.%s" % (modname, name), obj,
                              _call_patterns(("tdem." + modname,), name)))
    return [it for it in items if it.label not in ALLOWED]


ITEMS = _items()


def _literal(text):
    try:
        return True, ast.literal_eval(text)
    except (ValueError, SyntaxError):
        pass
    if _INF_LITERAL.match(text):
        return True, float(text)
    return False, None


def _check(item):
    """(problems, defaults problems) of one item."""
    mentions = _mentions(item.patterns)
    if not mentions:
        return ["not documented"], []
    line, col, _ = _defining(mentions)
    a, b = DOC.entry(line)
    code = DOC.code(a, b)
    where = "api.md line %d" % (line + 1)
    missing = [p for p in item.params if not re.search(r"(?<!\w)%s(?!\w)" % re.escape(p), code)]
    problems = ["parameter %r missing from its entry (%s)" % (p, where) for p in missing]
    wrong = []
    args = _signature_args(line, col)
    if DOC.lines[line].startswith("|"):
        args += re.findall(r"`([^`=]+=[^`]+)`", DOC.lines[line])
    for arg in args:
        name, eq, value = arg.lstrip("*").partition("=")
        name, value = name.strip(), value.strip()
        if not eq or name not in item.params:
            continue
        default = item.params[name]
        ok, doc_value = _literal(value)
        if ok and default is not inspect.Parameter.empty and doc_value != default:
            wrong.append("default %s=%s in api.md (%s), %r in the code"
                         % (name, value, where, default))
    return problems, wrong


def test_items_found():
    labels = {it.label for it in ITEMS}
    for label in ("Simulation.add_particles", "Simulation.run", "Wall.servo",
                  "LinearContact()", "tdem.pack.random", "plot_history"):
        assert label in labels, label
    assert len(ITEMS) > 80


def test_every_public_name_and_parameter_is_documented():
    report = []
    for item in ITEMS:
        problems, _ = _check(item)
        report += ["%s: %s" % (item.label, p) for p in problems]
    assert not report, (
        "docs/api.md lags the code (document each below, with meaning, units and "
        "default):\n  " + "\n  ".join(report))


def test_documented_defaults_match_the_code():
    report = []
    for item in ITEMS:
        _, wrong = _check(item)
        report += ["%s: %s" % (item.label, w) for w in wrong]
    assert not report, "docs/api.md states defaults the code does not have:\n  " + \
        "\n  ".join(report)


@pytest.mark.parametrize("label", sorted(ALLOWED | INTERNAL_CONSTRUCTORS))
def test_allowed_names_exist(label):
    """An allow-list entry that no longer names anything is removed."""
    owner, _, member = label.rstrip("()").partition(".")
    assert hasattr(tdem, owner) and (member == "" or hasattr(getattr(tdem, owner), member)), label
