#!/usr/bin/python3
"""Writes the validation report (docs/validation.md and docs/figures/*.png): runs every section
module of docs/validation/sections/ in order and joins their markdown under a header.

Run through scripts/validation.sh, which builds the binaries and passes their paths:
    /usr/bin/python3 docs/validation/report.py --sim SIM --render RENDER [--grids GRIDS] --out DIR
                                               [--quick]

A section is a module `sections/NAME.py` with
    TITLE = "..."                  # the heading of its part of the report
    FIGURES = ["name", ...]        # the PNGs it must write (or skip with a reason), without .png
    def run(ctx) -> str            # runs its commands, saves figures, returns markdown
(see common.Context for what ctx offers). Add a section by adding its module name to SECTIONS.
"""
import argparse
import datetime
import importlib
import os
import platform
import shutil
import subprocess
import sys
import tempfile
import time
import traceback

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from common import Context, cpu_model  # noqa: E402

# The report's parts, in order. A name whose module does not exist yet is listed as pending.
SECTIONS = [
    "bdz_fpu",       # BDZ Figs. 1-3: the FPU chain
    "bdz_string",    # BDZ Figs. 4-6: the geometrically exact string
    "bdz_plate",     # BDZ Figs. 8, 9, 11: the von Karman plate
    # --- slots for sections being written by others (create sections/NAME.py to fill one) ---
    "bdz_timing",           # BDZ Figs. 7 and 10: compute times (Google Benchmark program)
    "marazzato_table1",     # Marazzato et al. Table 1 (hamiltone-sim wave)
    "marazzato_figs",       # Marazzato et al. Figs. 6, 12, 16 (fpu --slow-fast, wave-inhomogeneous)
    # ------------------------------------------------------------------------------------------
    "instrument",    # the synthesizer: piano brightness, inharmonicity, pitch glide, gong
    "string_grids",  # the string's grid rules on the piano: glide, phantom partials, cost
    "dynamics",      # loudness across velocity and register; the fortissimo passage's headroom
    "body",          # the bridge's two-stage decay, the pedal's sympathetic ring
    "damper",        # key-off: each partial's decay under the felt damper
]


def machine():
    cpu = cpu_model()
    if cpu == "unknown CPU":
        cpu = platform.processor() or platform.machine()
    return f"{cpu}, {os.cpu_count()} logical CPUs, {platform.system()} {platform.release()}"


def commit(source):
    def git(*args):
        done = subprocess.run(["git", "-C", source, *args], capture_output=True, text=True)
        return done.stdout.strip() if done.returncode == 0 else ""
    head = git("rev-parse", "--short=12", "HEAD") or "unknown"
    # The report's own outputs (rewritten by this run) do not count as changes to the code.
    changed = git("status", "--porcelain", "--untracked-files=no", "--", ".",
                  ":(exclude)docs/validation.md", ":(exclude)docs/figures")
    return head + (" (with uncommitted changes)" if changed else "")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sim", required=True)
    parser.add_argument("--render", required=True)
    parser.add_argument("--grids", help="bench/hamiltone_validate_grids (built with the benchmarks)")
    parser.add_argument("--out", required=True, help="writes OUT/validation.md and OUT/figures/")
    parser.add_argument("--quick", action="store_true", help="short runs (the ctest)")
    parser.add_argument("--only", help="comma-separated section names (development)")
    args = parser.parse_args()
    source = os.path.dirname(os.path.dirname(HERE))
    sim, render = os.path.abspath(args.sim), os.path.abspath(args.render)
    grids = os.path.abspath(args.grids) if args.grids else None
    figures = os.path.join(args.out, "figures")
    os.makedirs(figures, exist_ok=True)
    only = set(args.only.split(",")) if args.only else None

    parts, timings, failures, errors = [], [], [], []
    with tempfile.TemporaryDirectory(prefix="hamiltone-validation-") as scratch:
        for name in SECTIONS:
            if only is not None and name not in only:
                continue
            if not os.path.exists(os.path.join(HERE, "sections", name + ".py")):
                timings.append((name, "pending (not written yet)", None))
                continue
            module = importlib.import_module("sections." + name)
            work = os.path.join(scratch, name)
            os.makedirs(work)
            ctx = Context(name, sim, render, work, figures, args.quick, source, grids)
            print(f"validation: {name} ...", flush=True)
            start = time.monotonic()
            try:
                body = module.run(ctx)
            except Exception:  # a broken section is reported, and fails the run
                body = "**This section failed to run:**\n\n```\n" + traceback.format_exc() + "```\n"
                errors.append(f"{name}: crashed")
            seconds = time.monotonic() - start
            for fig in module.FIGURES:
                file = fig + ".png"
                if file not in ctx.saved and file not in dict(ctx.skipped):
                    errors.append(f"{name}: figure {file} neither written nor skipped")
            failures += [f"{name}: {f}" for f in ctx.failures]
            timings.append((module.TITLE, f"{seconds:.0f} s", len(ctx.failures)))
            parts.append(f"## {module.TITLE}\n\n{body.strip()}\n")
            print(f"validation: {name} done in {seconds:.0f} s"
                  + (f", {len(ctx.failures)} failed check(s)" if ctx.failures else ""), flush=True)
            shutil.rmtree(work, ignore_errors=True)

    mode = "reduced (`--quick`)" if args.quick else "full"
    header = [
        "# Validation report",
        "",
        "The numerical experiments of Bilbao, Ducceschi & Zama 2022 (BDZ) and Marazzato et al. "
        "2020, re-run on this code, and measurements of the synthesizer's sound. Every number "
        "below is parsed from the output of the command printed next to it; none is typed in. "
        "Where a measurement disagrees with the paper's claim the section says so.",
        "",
        "Regenerate (installs what is missing and builds `build/release`; the runs themselves "
        "take 2–4 minutes on 2 cores, most of it the benchmark; `--quick` for a reduced run, `--out DIR` to write "
        "elsewhere):",
        "",
        "    ./scripts/validation.sh",
        "",
        f"- Run: {mode}, {datetime.datetime.now().astimezone().strftime('%Y-%m-%d %H:%M %Z')}",
        f"- Commit: {commit(source)}",
        f"- Machine: {machine()}",
        f"- Binaries: `{os.path.relpath(sim, source)}`, `{os.path.relpath(render, source)}`; the "
        "commands below name them as in `build/release`, and their files are those of the "
        "run's scratch directory.",
        "",
        "| section | time | failed checks |",
        "|---|---|---|",
    ]
    for title, seconds, failed in timings:
        header.append(f"| {title} | {seconds} | {'' if failed is None else failed} |")
    header.append("")
    if failures or errors:
        header.append("**Failed checks:** " + "; ".join(failures + errors) + ".")
        header.append("")
    text = "\n".join(header) + "\n" + "\n".join(parts)
    with open(os.path.join(args.out, "validation.md"), "w") as f:
        f.write(text)
    print(f"validation: wrote {os.path.join(args.out, 'validation.md')}")
    for e in errors + failures:
        print(f"validation: FAILED {e}", file=sys.stderr)
    if errors or (failures and args.quick):
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
