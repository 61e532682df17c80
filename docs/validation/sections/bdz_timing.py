"""BDZ Figs. 7 and 10: compute time per simulated second against the time step k for
Störmer–Verlet, the split SAV scheme (38) and the implicit references — the discrete-gradient
scheme (67) on the string, the linearly implicit scheme (83) on the plate — from the Google
Benchmark program bench/hamiltone_bench_references (bench/implicit_bench.cpp)."""
import csv
import io
import os

import matplotlib.pyplot as plt
import numpy as np

from common import code, cpu_model, fmt

TITLE = "BDZ Figs. 7 and 10: compute times of SV, (38) and the implicit schemes"
FIGURES = ["bdz_fig7_string_timing", "bdz_fig10_plate_timing"]

# Benchmark names are PROBLEM/k:K/SCHEME/iterations:N.
SCHEMES = [("SV", "Störmer–Verlet (66)/(82)", "tab:blue", "o"),
           ("SAV_38", "split SAV (38)", "tab:green", "s"),
           ("implicit", "implicit: (67) string, (83) plate", "black", "^")]
PROBLEMS = [("String", "Fig. 7: the geometrically exact string (§4.2.3), α = 300, "
                       "h = 1.05 √(E/ρ) k", "discrete-gradient scheme (67)"),
            ("Plate", "Fig. 10: the von Kármán plate (§4.3.3), amplitude 1 thickness, grid (84)",
                      "linearly implicit scheme (83)")]


def bench_path(ctx):
    """bench/hamiltone_bench_references of the build tree that holds ctx.sim (sim/...)."""
    tree = os.path.dirname(os.path.dirname(os.path.abspath(ctx.sim)))
    return os.path.join(tree, "bench", "hamiltone_bench_references")


def machine():
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return cpu_model(), os.cpu_count(), load


def read_benchmark_csv(path):
    """Google Benchmark's --benchmark_out CSV (context lines first, then 'name,...' and rows):
    {(problem, k, scheme): row dict with floats where numeric}."""
    with open(path) as f:
        lines = f.read().splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("name,"))
    rows = {}
    for row in csv.DictReader(io.StringIO("\n".join(lines[start:]))):
        parts = row["name"].split("/")
        problem, scheme = parts[0], parts[2]
        if scheme.startswith("implicit"):
            row["implicit_name"] = scheme
            scheme = "implicit"
        k = float(row["k"]) if row.get("k") else float(parts[1].split(":", 1)[1])
        rows[problem, k, scheme] = row
    return rows


def value(row, key):
    try:
        return float(row[key])
    except (KeyError, TypeError, ValueError):
        return float("nan")


def run(ctx):
    out = []
    binary = bench_path(ctx)
    if not os.access(binary, os.X_OK):
        reason = (f"`{os.path.relpath(binary, ctx.source)}` does not exist: this build tree was "
                  "configured with -DHAMILTONE_BUILD_BENCH=OFF or the target "
                  "hamiltone_bench_references was not built (scripts/validation.sh without "
                  "--build-dir builds it; it needs Google Benchmark, libbenchmark-dev).")
        out.append("The timings of BDZ Figs. 7 and 10 come from the benchmark program, which is "
                   "missing here.\n")
        out.append(ctx.skip(FIGURES[0], reason))
        out.append(ctx.skip(FIGURES[1], reason))
        return "\n".join(out)

    result = ctx.path("references.csv")
    args = [binary, f"--benchmark_out={result}", "--benchmark_out_format=csv"]
    if ctx.quick:   # the largest k of each problem only: the smallest grids
        args.append("--benchmark_filter=String/k:1e-05/|Plate/k:4e-05/")
    cpu, cores, load = machine()
    text, seconds = ctx.run(args)
    command = ctx.commands[-1].replace(ctx.work + os.sep, "")   # the CSV as in the scratch dir
    rows = read_benchmark_csv(result)
    failed = [f"{p} k={k:g} {s}: {r.get('error_message')}" for (p, k, s), r in rows.items()
              if r.get("error_occurred", "").strip().lower() in ("true", "1")]

    out.append("**Claim (BDZ §4.2.3, Fig. 7; §4.3.3, Fig. 10).** The explicit scheme (38) has "
               "compute times of the same order as Störmer–Verlet and a few orders of "
               "magnitude below the fully implicit scheme (67) on the string; on the plate it "
               "is “far lower” than the linearly implicit (83) and “very nearly on par” with "
               "Störmer–Verlet. For SV and (38) on the string the time scales as 1/k² at small k "
               "(the grid follows k). The paper ran Matlab on a 2016 laptop; only the ratios "
               "are comparable.\n")
    out.append(f"**Machine.** {cpu}, {cores} logical CPUs (nproc), load average "
               f"{load:.1f} when the benchmark started. The timings are **one run on a shared "
               "machine** (other jobs were running): CPU time per step, each scheme single-"
               "threaded, converted to seconds per simulated second (CPU time per step / k, the "
               "counter `s_per_sim_s`). Every benchmark steps a fixed count (10000 explicit, "
               "500 string-implicit, 30 plate-implicit steps) rather than a whole simulated "
               f"second. The benchmark program took {seconds:.0f} s.\n")
    if "DEBUG" in text:
        out.append("Google Benchmark warned that its library (Debian's libbenchmark) was built "
                   "as DEBUG; that concerns the timing harness, not the timed code, which is "
                   "this project's Release build.\n")
    if failed:
        out.append("**Benchmarks that reported an error:** " + "; ".join(failed) + ".\n")

    for index, (problem, title, implicit_label) in enumerate(PROBLEMS):
        ks = sorted({k for p, k, _ in rows if p == problem}, reverse=True)
        if not ks:
            out.append(ctx.skip(FIGURES[index], f"no {problem} benchmark ran"))
            continue
        cost = {s: np.array([value(rows.get((problem, k, s), {}), "s_per_sim_s") for k in ks])
                for s, _, _, _ in SCHEMES}
        fig, ax = plt.subplots(figsize=(5.8, 4.2))
        for scheme, label, colour, marker in SCHEMES:
            ok = np.isfinite(cost[scheme])
            ax.loglog(np.array(ks)[ok], cost[scheme][ok], marker + "-", color=colour,
                      label=label if scheme != "implicit" else implicit_label)
        k_arr = np.array(ks)
        if np.isfinite(cost["SV"][-1]):
            ax.loglog(k_arr, cost["SV"][-1] * (k_arr[-1] / k_arr) ** 2, "k:", lw=0.8,
                      label="∝ 1/k² (through SV's finest)")
        ax.set_xticks(ks)
        ax.set_xticklabels([f"{k:g}" for k in ks], rotation=30, fontsize=7)
        ax.minorticks_off()
        ax.set_xlabel("time step k (s)")
        ax.set_ylabel("CPU time per simulated second (s)")
        ax.set_title(title.split(":")[0] + ": " + problem.lower())
        ax.legend(loc="upper right", fontsize=7)
        fig.tight_layout()
        out.append(f"### {title}\n")
        out.append(ctx.figure(fig, FIGURES[index], f"CPU seconds per simulated second against "
                                                   f"k, {problem.lower()}: SV, (38) and the "
                                                   f"{implicit_label}; one run on a shared "
                                                   f"machine ({cores} CPUs)."))
        table = ["| k (s) | unknowns | SV (s) | (38) (s) | implicit (s) | Newton iterations "
                 "per step | (38)/SV | implicit/(38) |", "|---|---|---|---|---|---|---|---|"]
        r38, rimp = [], []
        for i, k in enumerate(ks):
            imp = rows.get((problem, k, "implicit"), {})
            any_row = next(rows[problem, k, s] for s, _, _, _ in SCHEMES
                           if (problem, k, s) in rows)
            a = cost["SAV_38"][i] / cost["SV"][i]
            b = cost["implicit"][i] / cost["SAV_38"][i]
            r38.append(a)
            rimp.append(b)
            newton = value(imp, "newton_per_step")
            table.append(f"| {k:g} | {value(any_row, 'unknowns'):.0f} | {fmt(cost['SV'][i])} | "
                         f"{fmt(cost['SAV_38'][i])} | {fmt(cost['implicit'][i])} | "
                         + (f"{newton:.2f}" if newton > 0 else "— (linear solve)")
                         + f" | {a:.2f} | {b:.0f} |")
        out.append("**Measured** (the CSV's `s_per_sim_s`, `unknowns`, `newton_per_step`):\n\n"
                   + "\n".join(table) + "\n")
        r38, rimp = np.array(r38), np.array(rimp)
        good38, goodimp = r38[np.isfinite(r38)], rimp[np.isfinite(rimp)]
        if good38.size and goodimp.size:
            orders = np.log10(goodimp)
            verdict = []
            verdict.append(f"(38) costs {good38.min():.2f}–{good38.max():.2f}× SV"
                           + (" — within a small factor, as the paper says"
                              if good38.max() <= 2.0 else
                              " — **more than the paper's “same order / nearly on par”**"
                              if good38.max() > 3.0 else
                              " — the same order, as the paper says"))
            verdict.append(f"the implicit scheme costs {goodimp.min():.0f}–{goodimp.max():.0f}× "
                           f"(38), i.e. {orders.min():.1f}–{orders.max():.1f} orders of "
                           "magnitude"
                           + (" — as the paper says" if orders.min() >= 2.0 else
                              " — **less than the paper's “a few orders of magnitude” at "
                              f"k = {ks[int(np.nanargmin(rimp))]:g}**"
                              if problem == "String" else
                              " — far slower, as the paper says" if orders.min() >= 1.0 else
                              " — **not “far” slower here**"))
            out.append("**Verdict.** " + "; ".join(verdict) + ".\n")
            if problem == "String" and len(ks) >= 3:
                fine = slice(-3, None)
                slopes = {s: float(np.polyfit(np.log(k_arr[fine]),
                                              np.log(cost[s][fine]), 1)[0])
                          for s in ("SV", "SAV_38")}
                out.append(f"Slope of log time against log k over the three smallest k: SV "
                           f"{slopes['SV']:.2f}, (38) {slopes['SAV_38']:.2f} (the paper: −2)"
                           + (".\n" if all(-2.3 <= v <= -1.7 for v in slopes.values()) else
                              " — **not −2 here**.\n"))
            out.append(ctx.check(bool(np.all(goodimp > 1.0)),
                                 f"{problem.lower()}: the implicit scheme is slower than (38) at "
                                 "every k") + "\n")
    out.append(code(command))
    if ctx.quick:
        out.append("(`--quick`: only the largest k of each problem, the smallest grids.)\n")
    return "\n".join(out)
