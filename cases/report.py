"""Tables of the cases' results, made from their ``summary.json`` files.

    python -m cases.report                 # print the tables of out/*/summary.json
    python -m cases.report --write         # and rewrite the marked blocks of the docs
    python -m cases.report --run --write   # run every quick preset first (--threads 1)
    python -m cases.report --check         # exit 1 if the docs differ from the summaries
    python -m cases.report --archive out/soil_cutting   # keep a run's results in docs/
    python -m cases.report --validation    # write docs/validation.md from the kept ones

The blocks it rewrites lie between HTML comments, which the Markdown does not show:

- ``<!-- results:start -->`` ... ``<!-- results:end -->``: one row per case (its quick
  preset's wall time, how many checks pass), in README.md and docs/cases.md;
- ``<!-- results:CASE:start -->`` ... ``<!-- results:CASE:end -->``: every check of
  CASE (value, target and tolerance, pass) in docs/cases.md;
- ``# quick-times:start`` ... ``# quick-times:end`` in cases/_common.py: the measured
  quick-preset times that each case's ``--help`` shows.

Text outside the markers is left as it is. The numbers are those of the summaries
found; a case without one keeps its block and is named on stderr.

The validation report. ``--archive DIR`` keeps a finished run: its ``summary.json``
and its plots (``*.png``) are copied to ``docs/validation/CASE/PRESET/`` (the case
and preset read from the summary), where they are committed. ``--validation``
writes ``docs/validation.md`` from every kept run: an index (case, preset, wall time
and where it was measured, how many checks pass, the wall-time aims of the paper
presets) and, per run, each figure beside the paper's with its tolerance and
verdict, and the plots.
"""
import argparse
import json
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

from cases import _common as common

ROOT = Path(__file__).resolve().parents[1]
#: the order of the tables: the papers' order (docs/cases.md)
ORDER = ("nine_disc", "photoelastic", "biaxial", "triaxial_3d", "elastic_gravity", "uniaxial_compression",
         "wave_bar", "bearing_capacity", "soil_cutting", "contact_burst", "water_blocks",
         "plate_loading",
         "ellipsoid_compression", "impact_benchmarks", "angle_of_repose", "dam_break",
         "rotating_drum", "hopper_discharge", "bonded_rock", "wet_column")
#: a few words on each case for the overview table
WHAT = {
    "nine_disc": "nine discs compressed by four walls (Cundall & Strack)",
    "photoelastic": "197 discs in a box: force picture, wall forces (Cundall & Strack)",
    "biaxial": "biaxial tests with rolling resistance (Jiang et al.)",
    "triaxial_3d": "triaxial compression of spheres between six servo walls (Thornton)",
    "elastic_gravity": "rock under gravity, PCMM against FVM (Feng et al.)",
    "bearing_capacity": "a rigid strip footing pushed into soil: Prandtl's collapse load",
    "uniaxial_compression": "a rock sample compressed to failure (Feng et al.)",
    "wave_bar": "a velocity pulse along a 20 m bar (Feng et al.)",
    "soil_cutting": "a blade cutting Mohr–Coulomb soil (Feng et al.)",
    "contact_burst": "a TNT charge detonated on soft rock (Feng et al.)",
    "water_blocks": "water released against columns of blocks (Feng et al.)",
    "plate_loading": "a plate pressed into beds of circles and superellipses (Miyata et al.)",
    "ellipsoid_compression": "ellipsoids under a plate: forces on the plates (Miyata et al.)",
    "impact_benchmarks": "sphere impacts against Hertz and Coulomb theory (Chung & Ooi)",
    "angle_of_repose": "heaps of cubes beside heaps of spheres: angle of repose (Chen)",
    "dam_break": "a water column collapsing: its surge front (Martin & Moyce)",
    "rotating_drum": "a drum of spheres spun up: its regimes against the Froude number (Mellmann)",
    "bonded_rock": "rock as parallel-bonded discs: UCS, Brazilian, the BPM trends (Potyondy & Cundall)",
    "wet_column": "wet spheres stand where dry ones slump: liquid bridges (Willett, Lian)",
    "hopper_discharge": "a bin emptying through a slot: flow rate against Beverloo's law",
}


# ------------------------------------------------------------------ reading
def cases():
    """The cases in table order (those of ``cases._common.list_cases``)."""
    found = common.list_cases()
    return [c for c in ORDER if c in found] + sorted(c for c in found if c not in ORDER)


def load(root):
    """{case: summary} of ``root/CASE/summary.json`` (those that exist and follow the
    schema; the others are named on stderr)."""
    out = {}
    for case in cases():
        path = Path(root) / case / "summary.json"
        if not path.exists():
            print(f"report: no {path}", file=sys.stderr)
            continue
        s = json.loads(path.read_text())
        bad = common.validate(s)
        if bad:
            print(f"report: {path} does not follow the schema: {'; '.join(bad)}",
                  file=sys.stderr)
            continue
        out[case] = s
    return out


# ---------------------------------------------------------------- rendering
def _cell(text):
    return str(text).replace("|", "\\|").replace("\n", " ")


def verdict(s):
    """'pass', 'FAIL' or '–' (nothing compared) of a summary or a check."""
    return {True: "pass", False: "FAIL", None: "–"}[s["pass"]]


def render_row(s):
    """One row of the overview table for a summary."""
    n = s["counts"]
    return (f"| `{s['case']}` | {_cell(WHAT.get(s['case'], ''))} | "
            f"{common.duration(s['wall_time_s'])} | "
            f"{n['passed']} of {n['passed'] + n['failed']} | {verdict(s)} |")


def how_measured(summaries):
    """'--threads 1 on 2 CPU cores, 2026-12-04' from the summaries (where they agree)."""
    def one(key):
        vals = {s.get(key) for s in summaries}
        return vals.pop() if len(vals) == 1 else None
    threads, cores, date = one("threads"), one("cpu_count"), one("date")
    parts = []
    if threads:
        parts.append(f"--threads {threads}")
    if cores:
        parts.append(f"on {cores} CPU cores")
    text = " ".join(parts) or "as recorded in each summary"
    return f"{text}, {date}" if date else text


def render_overview(summaries):
    """The overview table: one row per case with a summary."""
    rows = [summaries[c] for c in cases() if c in summaries]
    lines = [f"Quick presets, wall time measured with {how_measured(rows)}; checks: the "
             "compared figures within their tolerance (`summary.json`).",
             "",
             "| case | what | quick preset | checks | all pass |",
             "| --- | --- | --- | --- | --- |"]
    lines += [render_row(s) for s in rows]
    return "\n".join(lines)


def render_check(c):
    """One row of a case's table of checks."""
    return (f"| {_cell(c['name'])} | {_cell(common.format_value(c))} | "
            f"{_cell(common.format_target(c))} | {verdict(c)} |")


def render_checks(s):
    """The table of every check of one summary."""
    n = s["counts"]
    which = f"{s['preset']} preset" + (f" ({s['variant']})" if s.get("variant") else "")
    lines = [f"`{s['case']}`, {which} ({common.duration(s['wall_time_s'])}, "
             f"{how_measured([s])}): {n['passed']} of {n['passed'] + n['failed']} compared "
             f"checks pass, {n['reported']} reported only (no tolerance). "
             "Tolerances and why: the notes in `summary.json`.",
             "",
             "| check | value | target | pass |",
             "| --- | --- | --- | --- |"]
    lines += [render_check(c) for c in s["checks"]]
    return "\n".join(lines)


# ------------------------------------------------------------------ markers
def replace_block(text, name, body, comment=("<!-- ", " -->")):
    """``text`` with the lines between the markers ``results:NAME:start`` and
    ``...:end`` (``name`` None: ``results:start``/``results:end``) replaced by ``body``;
    the text unchanged if it has no such markers."""
    tag = "results" if name is None else f"results:{name}"
    a, b = comment
    start, end = f"{a}{tag}:start{b}", f"{a}{tag}:end{b}"
    pat = re.compile(re.escape(start) + r"\n.*?" + re.escape(end), re.S)
    if not pat.search(text):
        return text
    return pat.sub(lambda m: f"{start}\n{body.rstrip()}\n{end}", text, count=1)


def render_quick_times(summaries):
    """The body of the quick-times block of cases/_common.py."""
    rows = [summaries[c] for c in cases() if c in summaries and summaries[c]["preset"] == "quick"]
    items = [f'"{s["case"]}": {s["wall_time_s"]:.0f}' for s in rows]
    lines, line = [], "    "
    for it in items:
        if len(line) + len(it) + 2 > 88:
            lines.append(line.rstrip())
            line = "    "
        line += it + ", "
    lines.append(line.rstrip())
    return ("QUICK_WALL_S = {\n" + "\n".join(lines) + "\n}\n"
            f'QUICK_MEASURED = "measured with {how_measured(rows)}"')


def update(summaries, readme, docs, common_py):
    """{path: new text} of the files whose marked blocks change."""
    changed = {}
    overview = render_overview(summaries)
    for path in (readme, docs):
        if path is None or not Path(path).exists():
            continue
        old = Path(path).read_text()
        new = replace_block(old, None, overview)
        if path == docs:
            for case, s in summaries.items():
                new = replace_block(new, case, render_checks(s))
        if new != old:
            changed[path] = new
    quick = {c: x for c, x in summaries.items() if x["preset"] == "quick"}
    if common_py is not None and Path(common_py).exists() and quick:
        old = Path(common_py).read_text()
        new = _replace_quick_times(old, render_quick_times(quick))
        if new != old:
            changed[common_py] = new
    return changed


def _replace_quick_times(text, body):
    pat = re.compile(r"(# quick-times:start\n).*?(\n# quick-times:end)", re.S)
    return pat.sub(lambda m: m.group(1) + body + m.group(2), text, count=1)


# ------------------------------------------------------------ validation report
#: where the kept runs lie (CASE/PRESET/summary.json and plots) and the report
VALIDATION = ROOT / "docs" / "validation"
VALIDATION_MD = ROOT / "docs" / "validation.md"
#: wall-time aims of paper presets on 2 cores (seconds)
PAPER_TIME_AIM = {"contact_burst": 600.0, "soil_cutting": 7200.0}
PRESET_ORDER = ("paper", "quick")


def archive(run_dir, root=VALIDATION):
    """Copy a finished run's summary.json and plots to ``root/CASE/PRESET/`` (replacing
    what was kept there); returns that folder. Refuses a folder without a summary or
    with one that does not follow the schema, naming it."""
    run_dir = Path(run_dir)
    path = run_dir / "summary.json"
    if not path.exists():
        raise ValueError(f"--archive {run_dir}: no summary.json there (a finished run's "
                         "output folder is needed)")
    s = json.loads(path.read_text())
    bad = common.validate(s)
    if bad:
        raise ValueError(f"--archive {run_dir}: its summary.json does not follow the "
                         f"schema: {'; '.join(bad)}")
    dest = Path(root) / s["case"] / folder_name(s)
    if dest.exists():
        shutil.rmtree(dest)
    dest.mkdir(parents=True)
    shutil.copy2(path, dest / "summary.json")
    for png in sorted(run_dir.glob("*.png")):
        shutil.copy2(png, dest / png.name)
    return dest


def folder_name(s):
    """Where a run is kept under its case: PRESET, or PRESET-VARIANT for a variant."""
    return s["preset"] + (f"-{s['variant']}" if s.get("variant") else "")


def label(s):
    """The preset column of a kept run: 'paper', or 'paper, cells-four' for a variant."""
    return s["preset"] + (f", {s['variant']}" if s.get("variant") else "")


def kept(root=VALIDATION):
    """[(case, folder, summary, plot names)] of the kept runs, in table order: each
    preset's own run, then its variants (folders PRESET-VARIANT) by name."""
    out = []
    root = Path(root)
    for case in cases():
        for preset in PRESET_ORDER:
            here = root / case
            folders = [here / preset] + sorted(here.glob(f"{preset}-*"))
            for folder in folders:
                path = folder / "summary.json"
                if path.exists():
                    s = json.loads(path.read_text())
                    plots = sorted(p.name for p in folder.glob("*.png"))
                    out.append((case, folder.name, s, plots))
    return out


def _aim(case, preset, s):
    """The wall-time aim's cell: '≤ 10 min: met' etc., or '' where there is none."""
    aim = (PAPER_TIME_AIM.get(case) if s.get("preset") == "paper" and not s.get("variant")
           else None)
    if aim is None:
        return ""
    cores = s.get("cpu_count")
    met = "met" if s["wall_time_s"] <= aim else "over"
    where = f" on {cores} cores" if cores else ""
    return f"≤ {common.duration(aim)}{where}: {met}"


def _heading(case, s):
    """The section heading of a kept run in docs/validation.md."""
    return f"`{case}`, {label(s)}" + ("" if s.get("variant") else " preset")


def _slug(heading):
    """The anchor GitHub and MyST (``myst_heading_anchors``) give a heading: lower case,
    punctuation other than ``-`` and ``_`` dropped, spaces made ``-``."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def render_validation(runs, link="validation"):
    """The text of docs/validation.md for the kept runs ``runs`` (:func:`kept`);
    ``link``: the kept runs' folder relative to the report."""
    lines = ["# Validation", "",
             "Every case's figures beside the paper's, from the runs kept in "
             "`docs/validation/` (each run's `summary.json` and plots). Made by "
             "`python -m cases.report --validation`; a run is kept with "
             "`python -m cases.report --archive OUT_DIR`. The quick presets of every "
             "case, run in the test suite's time, are in [cases.md](cases.md).", "",
             "| case | preset | wall time | measured | checks | all pass | time aim |",
             "| --- | --- | --- | --- | --- | --- | --- |"]
    for case, preset, s, _ in runs:
        n = s["counts"]
        lines.append(f"| [`{case}`](#{_slug(_heading(case, s))}) | {label(s)} | "
                     f"{common.duration(s['wall_time_s'])} | {_cell(how_measured([s]))} | "
                     f"{n['passed']} of {n['passed'] + n['failed']} | {verdict(s)} | "
                     f"{_aim(case, preset, s)} |")
    for case, preset, s, plots in runs:
        lines += ["", f"## {_heading(case, s)}", ""]
        if s.get("paper"):
            what = _cell(WHAT.get(case, ""))
            lines += [f"{what[:1].upper()}{what[1:]}; paper: {s['paper']}.", ""]
        lines.append(render_checks(s))
        notes = s.get("notes")
        if notes:
            lines += ["", f"Notes: {_cell(notes)}"]
        if plots:
            for p in plots:
                lines += ["", f"![{p}]({link}/{case}/{preset}/{p})"]
    return "\n".join(lines) + "\n"


# ------------------------------------------------------------------ running
def run_cases(root, names, threads=1):
    """Run the quick preset of each case into ``root/CASE`` (one after the other)."""
    for case in names:
        t0 = time.perf_counter()
        cmd = [sys.executable, "-m", f"cases.{case}", "--preset", "quick",
               "--threads", str(threads), "--out", str(Path(root) / case)]
        print(f"report: {' '.join(cmd[1:])}", file=sys.stderr, flush=True)
        r = subprocess.run(cmd, cwd=ROOT)
        print(f"report: {case} exited {r.returncode} after "
              f"{time.perf_counter() - t0:.0f} s", file=sys.stderr, flush=True)


def main(argv=None):
    p = argparse.ArgumentParser(prog="python -m cases.report",
                                description="Tables of the cases' results from their "
                                            "summary.json files (docs/cases.md).")
    p.add_argument("--out-root", default="out", metavar="DIR",
                   help="folder with one subfolder per case (default: out)")
    p.add_argument("--run", action="store_true",
                   help="run the quick preset of every case first (or of --cases)")
    p.add_argument("--cases", nargs="+", default=None, metavar="CASE",
                   help="with --run: only these cases")
    p.add_argument("--threads", type=int, default=1, help="with --run (default 1)")
    p.add_argument("--write", action="store_true",
                   help="rewrite the marked blocks of README.md, docs/cases.md and the "
                        "quick-preset times of cases/_common.py")
    p.add_argument("--check", action="store_true",
                   help="exit 1 if a marked block differs from the summaries")
    p.add_argument("--archive", nargs="+", default=None, metavar="DIR",
                   help="keep these finished runs (summary.json and plots) in "
                        "docs/validation/CASE/PRESET/, then write docs/validation.md")
    p.add_argument("--validation", action="store_true",
                   help="write docs/validation.md from the runs kept in docs/validation/")
    args = p.parse_args(argv)
    if args.archive or args.validation:
        for d in args.archive or ():
            try:
                dest = archive(d)
            except ValueError as e:
                p.error(str(e))
            print(f"report: kept {d} in {dest.relative_to(ROOT)}", file=sys.stderr)
        runs = kept()
        VALIDATION_MD.write_text(render_validation(runs))
        print(f"report: wrote {VALIDATION_MD.relative_to(ROOT)} ({len(runs)} runs)",
              file=sys.stderr)
        return 0
    if args.run:
        names = args.cases or cases()
        unknown = [c for c in names if c not in cases()]
        if unknown:
            p.error(f"unknown cases {unknown}; the cases are {cases()}")
        run_cases(args.out_root, names, args.threads)
    summaries = load(args.out_root)
    if not summaries:
        print(f"report: no summaries under {args.out_root}/", file=sys.stderr)
        return 1
    print(render_overview(summaries))
    for case, s in summaries.items():
        print()
        print(render_checks(s))
    changed = update(summaries, ROOT / "README.md", ROOT / "docs" / "cases.md",
                     ROOT / "cases" / "_common.py")
    if args.write:
        for path, text in changed.items():
            Path(path).write_text(text)
            print(f"report: wrote {Path(path).relative_to(ROOT)}", file=sys.stderr)
    elif args.check and changed:
        print("report: out of date: " + ", ".join(str(Path(c).relative_to(ROOT))
                                                 for c in changed), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
