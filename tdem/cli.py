"""The ``tdem`` command: list the case scripts and run one.

    tdem list
    tdem run CASE [--preset quick|paper] [--arch cpu|gpu] [--out DIR] [...]
    tdem view DIR [--png FILE] [--time T] [...]   (a ParaView picture of an output folder)

Everything after ``CASE`` goes to the case's own ``main(argv)`` unchanged.
"""
import argparse
import importlib
import sys


def _cases():
    from cases._common import list_cases
    return list_cases()


def _parser():
    p = argparse.ArgumentParser(prog="tdem", description="tdem: run the case scripts "
                                "of the project (python -m cases.NAME does the same).")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.add_parser("list", help="list the cases with a one-line description")
    run = sub.add_parser("run", help="run a case: tdem run CASE [--preset quick|paper] ...",
                         add_help=False)
    run.add_argument("case", metavar="CASE")
    run.add_argument("args", nargs=argparse.REMAINDER,
                     help="options of the case (--preset, --arch, --out, ...)")
    sub.add_parser("view", add_help=False,
                   help="write DIR/view.py (ParaView) for an output folder and run it in "
                        "pvpython, saving DIR/view.png: tdem view DIR [--png FILE] ...")
    return p


def main(argv=None):
    """Entry point of the ``tdem`` console script; returns the exit status."""
    argv = list(sys.argv[1:] if argv is None else argv)
    p = _parser()
    if not argv:
        p.print_help()
        return 2
    if argv[0] == "view":
        from .paraview import main as view_main
        return view_main(argv[1:])
    cases = _cases()
    if argv[0] == "run" and (len(argv) == 1 or argv[1] in ("-h", "--help")):
        print("usage: tdem run CASE [--preset quick|paper] [--arch cpu|gpu] [--out DIR] "
              "[--threads N] [case options]\n\n'tdem run CASE --help' shows a case's "
              "options. The cases:")
        width = max((len(n) for n in cases), default=0)
        for name, desc in cases.items():
            print(f"  {name:<{width}}  {desc}")
        return 0 if len(argv) > 1 else 2
    # "tdem run CASE --help" reaches the case's own parser (argparse.REMAINDER)
    ns = p.parse_args(argv)
    if ns.command == "list":
        width = max((len(n) for n in cases), default=0)
        for name, desc in cases.items():
            print(f"{name:<{width}}  {desc}")
        return 0
    if ns.command == "run":
        if ns.case not in cases:
            print(f"tdem: unknown case {ns.case!r}; the cases are: "
                  f"{', '.join(cases) or '(none)'} (see 'tdem list')", file=sys.stderr)
            return 2
        from cases import _common
        module = importlib.import_module(f"cases.{ns.case}")
        _common.COMMAND = f"tdem run {ns.case}"
        try:
            result = module.main(ns.args)
        finally:
            _common.COMMAND = None
        return result if isinstance(result, int) else 0
    p.print_help()
    return 2


if __name__ == "__main__":
    sys.exit(main())
