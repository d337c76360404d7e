#!/usr/bin/env python3
"""Peer comparison of lobes against Mitsuba 3's chi-square test (issue 8, item 3).

In one run on one machine, for GGX and Beckmann x NDF sampling and visible-normal
sampling, at the same alpha, incident direction and sample count, this measures

  Mitsuba 3  mitsuba.chi2.ChiSquareTest on the `roughconductor` plugin
             (SphericalDomain, BSDFAdapter), variant llvm_ad_rgb by default:
             tabulate_histogram() (sampling + histogram), tabulate_pdf()
             (expected histogram by the trapezoid rule on ires x ires points per
             cell), and the whole test (construct + run()), each timed with
             time.perf_counter() around the call, after one untimed warm-up
             (Dr.Jit compiles its kernels on first use); median of --runs.
  lobes      `lobes bench --json --gpu-only` (sampling + histogram, GPU
             timestamps, median of --runs), and per case a one-case scene through
             `lobes run SCENE --out DIR --json`: `quadrature_seconds` from
             DIR/<case>/timing.json (the f64 expected histogram) and the wall
             time of the whole process (the whole test); median of --runs.

The whole batch (issue 14): the four cases as ONE process each, from process start to
verdicts, with warm caches (one untimed run first), median of --runs: `lobes run` of a
4-case scene against a Python process that imports Mitsuba and runs the four
ChiSquareTest(..., res, ires=32).run(), at --batch-incident-theta (default 40 deg).

The Mesa version of lobes' adapter is printed (from its adapter line). --mesa-env FILE
(a shell file that exports VK_DRIVER_FILES / LD_LIBRARY_PATH for a private lavapipe, see
docs/install-mesa.md) repeats every lobes measurement on that driver in the same run.

The lobes scenes use bins = [2*res/2, res/2] = [128, 64] for res = 128, i.e. 128
rows over cos(theta) by 64 columns over phi: exactly Mitsuba's grid (its sphere
domain has res.x = res/2 cells over phi and res.y = res cells over cos(theta)),
so the two expected histograms are compared cell by cell (accuracy columns).
`lobes bench` has fixed 64 x 128 bins: the same number of equal-area cells.

This is a tool of the repository, not a dependency of the crate. Set-up and the
caveats of the comparison: bench/README.md.
"""

import argparse
import json
import math
import os
import platform
import re
import shlex
import statistics
import subprocess
import sys
import tempfile
import time

BATCH_IRES = 32  # the batch's Mitsuba trapezoid points per cell side (its rough-conductor tests' value)

CASES = [  # (lobe, lobes method, Mitsuba sample_visible)
    ("ggx", "ndf", False),
    ("ggx", "vndf", True),
    ("beckmann", "ndf", False),
    ("beckmann", "vndf", True),
]


def die(msg):
    print(f"mitsuba_compare.py: error: {msg}", file=sys.stderr)
    sys.exit(2)


def import_mitsuba(variant):
    llvm = os.environ.get("DRJIT_LIBLLVM_PATH")
    if variant.startswith("llvm") and not llvm:
        for cand in ("/usr/lib/x86_64-linux-gnu/libLLVM-19.so",
                     "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1",
                     "/usr/lib/x86_64-linux-gnu/libLLVM-19.so.1"):
            if os.path.exists(cand):
                os.environ["DRJIT_LIBLLVM_PATH"] = cand
                print(f"# DRJIT_LIBLLVM_PATH not set; using {cand}", file=sys.stderr)
                break
    try:
        import drjit as dr  # noqa: F401
        import mitsuba as mi
    except ImportError as e:
        die(f"cannot import Mitsuba 3 ({e}).\n"
            "  Install it with: pip install mitsuba==3.9.1 drjit==1.5.0\n"
            "  and for the LLVM variant Debian's libllvm19 (apt-get install libllvm19),\n"
            "  then DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so. See bench/README.md.")
    try:
        mi.set_variant(variant)
        # Force the backend up now, so that a broken LLVM fails here with a clear message.
        if not variant.startswith("scalar"):
            x = mi.Float([1.0, 2.0])
            _ = float(dr.sum(x)[0])
    except Exception as e:  # noqa: BLE001
        die(f"Mitsuba variant {variant!r} does not work here: {e}\n"
            f"  DRJIT_LIBLLVM_PATH={os.environ.get('DRJIT_LIBLLVM_PATH')!r}. Debian 12's LLVM 15 fails\n"
            "  ('Cannot select fmaximum'); use libllvm19, or --variant scalar_rgb (much slower).")
    import mitsuba.chi2 as chi2
    return mi, dr, chi2


def median(xs):
    return statistics.median(xs)


def measure_mitsuba(mi, dr, chi2, args, lobe, visible, ires):
    th = math.radians(args.incident_theta)
    ph = math.radians(args.incident_phi)
    wi = [math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th)]
    spec = {"type": "roughconductor", "distribution": lobe, "alpha": args.alpha,
            "sample_visible": visible}
    sample_func, pdf_func = chi2.BSDFAdapter("roughconductor", spec, wi=wi)

    def make():
        return chi2.ChiSquareTest(domain=chi2.SphericalDomain(), sample_func=sample_func,
                                  pdf_func=pdf_func, sample_dim=3,
                                  sample_count=args.samples, res=args.res, ires=ires)

    hist_t, pdf_t, whole_t = [], [], []
    last = None
    for i in range(args.runs + 1):  # run 0 is the warm-up (kernel compilation), not counted
        t = make()
        t0 = time.perf_counter()
        t.tabulate_histogram()
        t1 = time.perf_counter()
        t.tabulate_pdf()
        t2 = time.perf_counter()
        t.run(significance_level=0.01, quiet=True)
        # whole test, separately: a fresh test object, construct + run()
        t3 = time.perf_counter()
        w = make()
        ok = w.run(significance_level=0.01, quiet=True)
        t4 = time.perf_counter()
        if i > 0:
            hist_t.append(t1 - t0)
            pdf_t.append(t2 - t1)
            whole_t.append(t4 - t3)
        last = (t, w, ok)
    t, w, ok = last
    import numpy as np
    res = (int(t.res[0]), int(t.res[1]))  # (cells over phi, cells over cos theta)
    pdf = np.array(t.pdf, dtype=np.float64).reshape(res[1], res[0])  # [y][x]
    return {
        "hist_seconds": median(hist_t), "hist_all": hist_t,
        "pdf_seconds": median(pdf_t), "pdf_all": pdf_t,
        "whole_seconds": median(whole_t), "whole_all": whole_t,
        "passed": bool(ok), "p_value": float(w.p_value[0] if hasattr(w.p_value, "__len__") else w.p_value),
        "messages": w.messages.strip().replace("\n", " | "),
        "res_phi": res[0], "res_cos": res[1], "expected": pdf,
    }


def mesa_version(adapter):
    """'25.0.7-2~bpo12+1' from lavapipe's adapter line ('... llvmpipe Mesa 25.0.7-2~bpo12+1 (LLVM ...)')."""
    m = re.search(r"Mesa ([0-9][^ )]*)", adapter)
    return m.group(1) if m else "n/a"


def env_from_file(path):
    """The environment after sourcing the shell file `path` (e.g. /work/mesa25/env.sh)."""
    p = subprocess.run(["bash", "-c", f". {shlex.quote(path)} && env -0"], capture_output=True, text=True)
    if p.returncode != 0:
        die(f"cannot source {path}: {p.stderr.strip()}")
    return dict(kv.split("=", 1) for kv in p.stdout.split("\0") if "=" in kv)


def run_lobes_bench(args, env):
    cmd = [args.lobes, "bench", "--json", "--gpu-only", "--samples", str(args.samples),
           "--runs", str(args.runs), "--alpha", repr(args.alpha)]
    print("# " + " ".join(cmd), file=sys.stderr)
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        die(f"{' '.join(cmd)} exited with {p.returncode}:\n{p.stderr}")
    out = json.loads(p.stdout)
    by = {(r["lobe"], r["method"]): r for r in out["results"] if r["backend"] == "gpu"}
    return out["adapter"], by


def case_toml(args, lobe, method, theta):
    """A lobes scene's [[case]] of `lobe` and `method` at incidence `theta` (degrees)."""
    return f"""
[[case]]
name = "{lobe}-{method}"
lobe = "{lobe}"
method = "{method}"
alpha = {args.alpha!r}
incident_theta = {theta!r}
incident_phi = {args.incident_phi!r}
"""


def scene_toml(args, bins, cases):
    return f"[defaults]\nsamples = {args.samples}\nbins = [{bins[0]}, {bins[1]}]\nseed = 1\n" + cases


def run_lobes_case(args, lobe, method, workdir, bins, env):
    import numpy as np
    name = f"{lobe}-{method}"
    scene = os.path.join(workdir, f"{name}.toml")
    with open(scene, "w") as f:
        f.write(scene_toml(args, bins, case_toml(args, lobe, method, args.incident_theta)))
    quad, whole, hist_wall = [], [], []
    d = None
    for i in range(args.runs):
        out = os.path.join(workdir, f"{name}-out{i}")
        cmd = [args.lobes, "run", scene, "--out", out, "--json"]
        if i == 0:
            print("# " + " ".join(cmd), file=sys.stderr)
        t0 = time.perf_counter()
        p = subprocess.run(cmd, capture_output=True, text=True, env=env)
        t1 = time.perf_counter()
        if p.returncode not in (0, 1):  # 1 = a case failed its test; still a measurement
            die(f"{' '.join(cmd)} exited with {p.returncode}:\n{p.stderr}")
        with open(os.path.join(out, name, "histogram.json")) as f:
            d = json.load(f)
        with open(os.path.join(out, name, "timing.json")) as f:
            timing = json.load(f)
        quad.append(timing["quadrature_seconds"])
        hist_wall.append(timing["histogram"].get("histogram_wall_seconds", float("nan")))
        whole.append(t1 - t0)
    expected = np.array(d["expected"], dtype=np.float64).reshape(d["rows"], d["cols"])
    return {
        "quad_seconds": median(quad), "quad_all": quad,
        "whole_seconds": median(whole), "whole_all": whole,
        "hist_wall_seconds": median(hist_wall),
        "passed": d["chi2"]["passed"], "p_value": d["chi2"]["p_value"],
        "quad_error_estimate": d["quadrature"]["error_estimate"],
        "expected": expected, "rows": d["rows"], "cols": d["cols"],
    }


def batch_scene(args, bins):
    return scene_toml(args, bins, "".join(case_toml(args, lobe, method, args.batch_incident_theta)
                                          for lobe, method, _ in CASES))


MITSUBA_BATCH = """
import math, sys
import drjit as dr
import mitsuba as mi
mi.set_variant({variant!r})
import mitsuba.chi2 as chi2
th, ph = math.radians({theta!r}), math.radians({phi!r})
wi = [math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th)]
verdicts = []
for lobe, visible in {cases!r}:
    spec = {{"type": "roughconductor", "distribution": lobe, "alpha": {alpha!r}, "sample_visible": visible}}
    sample_func, pdf_func = chi2.BSDFAdapter("roughconductor", spec, wi=wi)
    t = chi2.ChiSquareTest(domain=chi2.SphericalDomain(), sample_func=sample_func, pdf_func=pdf_func,
                           sample_dim=3, sample_count={samples}, res={res}, ires={ires})
    verdicts.append(bool(t.run(significance_level=0.01, quiet=True)))
print(" ".join("pass" if v else "FAIL" for v in verdicts))
"""


def time_process(cmd, env, runs, what):
    """Wall seconds of `cmd` from start to exit: one untimed warm-up, then `runs` timed; (median, all, stdout)."""
    print("# " + what + ": " + " ".join(shlex.quote(c) for c in cmd), file=sys.stderr)
    ts, out = [], ""
    for i in range(runs + 1):
        t0 = time.perf_counter()
        p = subprocess.run(cmd, capture_output=True, text=True, env=env)
        t1 = time.perf_counter()
        if p.returncode not in (0, 1):  # 1 = lobes: a case failed its test; still a measurement
            die(f"{what} exited with {p.returncode}:\n{p.stderr}")
        out = p.stdout
        if i > 0:
            ts.append(t1 - t0)
    return median(ts), ts, out


def run_mitsuba_batch(args, workdir):
    script = os.path.join(workdir, "mitsuba_batch.py")
    with open(script, "w") as f:
        f.write(MITSUBA_BATCH.format(variant=args.variant, theta=args.batch_incident_theta, phi=args.incident_phi,
                                     cases=[(lobe, vis) for lobe, _, vis in CASES], alpha=args.alpha,
                                     samples=args.samples, res=args.res, ires=BATCH_IRES))
    s, ts, out = time_process([sys.executable, script], dict(os.environ), args.runs, "Mitsuba batch")
    return {"seconds": s, "all": ts, "verdicts": out.strip()}


def run_lobes_batch(args, workdir, bins, env, label):
    scene = os.path.join(workdir, "batch.toml")
    with open(scene, "w") as f:
        f.write(batch_scene(args, bins))
    out = os.path.join(workdir, f"batch-out-{label}")
    s, ts, _ = time_process([args.lobes, "run", scene, "--out", out], env, args.runs, f"lobes batch ({label})")
    with open(os.path.join(out, "summary.json")) as f:
        summary = json.load(f)
    verdicts = " ".join("pass" if c["passed"] else "FAIL" for c in summary["cases"])
    return {"seconds": s, "all": ts, "verdicts": verdicts}


def measure_lobes(args, workdir, bins, env, label):
    """Every lobes measurement on one driver (`env`): bench, the one-case scenes, the batch."""
    print(f"# load average before lobes ({label}): {loadavg()}", file=sys.stderr)
    os.makedirs(os.path.join(workdir, label), exist_ok=True)
    adapter, bench = run_lobes_bench(args, env)
    cases = {}
    for lobe, method, _ in CASES:
        cases[(lobe, method)] = run_lobes_case(args, lobe, method, os.path.join(workdir, label), bins, env)
    batch = run_lobes_batch(args, os.path.join(workdir, label), bins, env, label)
    print(f"# lobes adapter ({label}): {adapter}", file=sys.stderr)
    return {"label": label, "adapter": adapter, "mesa": mesa_version(adapter), "bench": bench, "cases": cases, "batch": batch}


def compare_expected(m, l):
    """Mitsuba's trapezoid table against lobes' adaptive f64 quadrature, same grid.

    Mitsuba cell (x, y): phi in [-pi + x*dphi, ..), p.y in [-1 + y*dc, ..) with cos theta = -p.y.
    lobes cell (row, col): cos theta in [-1 + row*dc, ..), phi in [-pi + col*dphi, ..).
    So lobes row = res_cos - 1 - y and col = x.
    """
    import numpy as np
    me = m["expected"]
    if (l["rows"], l["cols"]) != (m["res_cos"], m["res_phi"]):
        return None
    mt = me[::-1, :]  # row r of lobes <- y = res_cos - 1 - r
    le = l["expected"]
    diff = mt - le
    l1 = float(np.abs(diff).sum() / le.sum())
    mask = le > 5
    sig = float(np.max(np.abs(diff[mask]) / np.sqrt(le[mask]))) if mask.any() else float("nan")
    return {"rel_l1": l1, "max_sigma": sig}


PROBE_VARIANTS = [("A_wg", "sample + workgroup-atomic histogram"),
                  ("B_none", "sample + bin, no histogram"),
                  ("D_noatan", "sample + row only, no histogram")]


def run_probe(args, workdir, env):
    """bench/probe's kernels at 2^24 samples (1024 workgroups x 16384): samples/s per variant."""
    here = os.path.dirname(os.path.abspath(__file__))
    binary = os.path.join(os.path.dirname(args.lobes), "examples", "kernel_probe")
    if not os.access(binary, os.X_OK):
        die(f"--probe: {binary} not found; run `cargo build --release --example kernel_probe`")
    out = {}
    for name, _ in PROBE_VARIANTS:
        path = os.path.join(workdir, f"probe_{name}.wgsl")
        with open(path, "w") as f:
            for part in ("common.wgsl", f"{name}.wgsl"):
                with open(os.path.join(here, "probe", part)) as src:
                    f.write(src.read())
        cmd = [binary, path, "1024", "8192", "16384", str(max(args.runs, 5))]
        print("# " + " ".join(cmd), file=sys.stderr)
        line = subprocess.run(cmd, env=env, check=True, capture_output=True, text=True).stdout
        out[name] = float(line.split("samples/s")[0].split()[-1])
    return out


def fmt(x, spec=".3g"):
    return "n/a" if x is None or (isinstance(x, float) and math.isnan(x)) else format(x, spec)


def loadavg():
    try:
        return " ".join(f"{v:.2f}" for v in os.getloadavg())
    except OSError:
        return "n/a"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--lobes", default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                    "..", "target", "release", "lobes"),
                    help="the lobes binary (default: target/release/lobes; build it with cargo build --release)")
    ap.add_argument("--samples", type=int, default=1 << 24)
    ap.add_argument("--alpha", type=float, default=0.3)
    ap.add_argument("--incident-theta", type=float, default=45.0, help="degrees from the normal")
    ap.add_argument("--incident-phi", type=float, default=0.0, help="degrees from +x towards +y")
    ap.add_argument("--batch-incident-theta", type=float, default=40.0,
                    help="degrees from the normal in the whole-batch measurement (issue 14's batch: 40)")
    ap.add_argument("--runs", type=int, default=3, help="timed runs per measurement; medians are reported")
    ap.add_argument("--res", type=int, default=128,
                    help="Mitsuba res: res cells over cos(theta) x res/2 over phi (even; 128 -> 8192 cells)")
    ap.add_argument("--ires", type=int, nargs="+", default=[4, 32],
                    help="Mitsuba trapezoid points per cell side (default 4 = ChiSquareTest's default, 32 = its rough-conductor tests)")
    ap.add_argument("--variant", default="llvm_ad_rgb", help="Mitsuba variant (llvm_ad_rgb or scalar_rgb)")
    ap.add_argument("--mesa-env", metavar="FILE",
                    help="also measure lobes with the environment this shell file exports (a private lavapipe, "
                         "e.g. Mesa 25 from bookworm-backports: docs/install-mesa.md)")
    ap.add_argument("--probe", action="store_true",
                    help="also run bench/probe's plain kernels (A_wg, B_none, D_noatan; needs "
                         "`cargo build --release --example kernel_probe`) on each driver, for the kernel ceiling")
    ap.add_argument("--json", metavar="FILE", help="also write all measurements to FILE")
    args = ap.parse_args()
    if args.res % 2:
        die("--res must be even so that lobes can use the same grid (the horizon is a row edge)")
    args.lobes = os.path.abspath(args.lobes)
    if not os.access(args.lobes, os.X_OK):
        die(f"lobes binary not found at {args.lobes}; run `cargo build --release` in the repository root")
    drivers = [("system", dict(os.environ))]
    if args.mesa_env:
        if not os.path.isfile(args.mesa_env):
            die(f"--mesa-env {args.mesa_env}: no such file")
        drivers.append(("mesa-env", env_from_file(args.mesa_env)))

    mi, dr, chi2 = import_mitsuba(args.variant)
    bins = (args.res, args.res // 2)

    print(f"# machine: {platform.node()} {platform.machine()}, {os.cpu_count()} logical CPUs; "
          f"Python {platform.python_version()}; mitsuba {mi.__version__}, drjit {dr.__version__}, "
          f"variant {mi.variant()}, DRJIT_LIBLLVM_PATH={os.environ.get('DRJIT_LIBLLVM_PATH')}", file=sys.stderr)
    print(f"# samples {args.samples}, alpha {args.alpha}, theta_i {args.incident_theta} deg "
          f"(batch {args.batch_incident_theta} deg), phi_i {args.incident_phi} deg, runs {args.runs}, Mitsuba res {args.res} "
          f"({args.res // 2} phi x {args.res} cos theta), ires {args.ires} (batch {BATCH_IRES})", file=sys.stderr)

    results = {}
    print(f"# load average before Mitsuba: {loadavg()}", file=sys.stderr)
    for lobe, method, vis in CASES:
        for ires in args.ires:
            print(f"# Mitsuba {lobe} sample_visible={vis} ires={ires} ...", file=sys.stderr)
            results[(lobe, method, "mitsuba", ires)] = measure_mitsuba(mi, dr, chi2, args, lobe, vis, ires)
    with tempfile.TemporaryDirectory(prefix="lobes-mitsuba-") as wd:
        mitsuba_batch = run_mitsuba_batch(args, wd)
        lobes = [measure_lobes(args, wd, bins, env, label) for label, env in drivers]
        if args.probe:
            for l, (label, env) in zip(lobes, drivers):
                l["probe"] = run_probe(args, wd, env)
    print(f"# load average after: {loadavg()}", file=sys.stderr)

    i0 = args.ires[0]
    out_drivers = []
    for l in lobes:
        print()
        print(f"## lobes on Mesa {l['mesa']} ({l['adapter']})")
        print()
        print("Sampling + histogram (2^%g samples); expected histogram; whole test. Medians of %d runs; seconds. Ratios > 1: lobes faster."
              % (math.log2(args.samples), args.runs))
        print()
        print("| lobe | method | Mitsuba samples/s | lobes samples/s | lobes / Mitsuba "
              + "".join(f"| Mitsuba pdf s (ires {r}) " for r in args.ires)
              + "| lobes quadrature s | lobes speed-up, pdf (Mitsuba ires %d s / lobes s) | Mitsuba whole s (ires %d) | lobes whole s | lobes speed-up, whole (Mitsuba s / lobes s) |" % (i0, i0))
        print("|---|---|---|---|---" + "|---" * len(args.ires) + "|---|---|---|---|---|")
        rows = []
        for lobe, method, vis in CASES:
            m = results[(lobe, method, "mitsuba", i0)]
            c = l["cases"][(lobe, method)]
            b = l["bench"].get((lobe, method))
            m_sps = args.samples / m["hist_seconds"]
            l_sps = b["samples_per_second"] if b else float("nan")
            pdfs = [results[(lobe, method, "mitsuba", r)]["pdf_seconds"] for r in args.ires]
            row = {
                "lobe": lobe, "method": method, "mitsuba_sample_visible": vis,
                "mitsuba_hist_seconds": m["hist_seconds"], "mitsuba_samples_per_second": m_sps,
                "lobes_bench_seconds": b["seconds"] if b else None, "lobes_samples_per_second": l_sps,
                "throughput_ratio_lobes_over_mitsuba": l_sps / m_sps,
                "mitsuba_pdf_seconds": dict(zip(map(str, args.ires), pdfs)),
                "lobes_quadrature_seconds": c["quad_seconds"],
                "mitsuba_whole_seconds": m["whole_seconds"], "lobes_whole_seconds": c["whole_seconds"],
                "lobes_run_histogram_wall_seconds": c["hist_wall_seconds"],
                "mitsuba_passed": m["passed"], "mitsuba_p_value": m["p_value"],
                "lobes_passed": c["passed"], "lobes_p_value": c["p_value"],
                "lobes_quadrature_error_estimate": c["quad_error_estimate"],
                "expected_vs_lobes": {str(r): compare_expected(results[(lobe, method, "mitsuba", r)], c)
                                      for r in args.ires},
                "raw": {"mitsuba": {str(r): {k: v for k, v in results[(lobe, method, "mitsuba", r)].items()
                                             if k != "expected"} for r in args.ires},
                        "lobes": {k: v for k, v in c.items() if k != "expected"}},
            }
            rows.append(row)
            print(f"| {lobe} | {method} | {m_sps:.3g} | {l_sps:.3g} | {l_sps / m_sps:.2f} "
                  + "".join(f"| {p:.3g} " for p in pdfs)
                  + f"| {c['quad_seconds']:.3g} | {m['pdf_seconds'] / c['quad_seconds']:.3g} "
                  + f"| {m['whole_seconds']:.3g} | {c['whole_seconds']:.3g} | {m['whole_seconds'] / c['whole_seconds']:.2f} |")

        print()
        print("Verdicts and accuracy of Mitsuba's expected histogram against lobes' f64 adaptive quadrature "
              "(same %d x %d grid): relative L1 of the difference, and its largest |difference| / sqrt(expected) "
              "over cells with expected > 5 (1 = one standard deviation of a count at this sample size)." %
              (args.res, args.res // 2))
        print()
        print("| lobe | method | Mitsuba p (verdict) | lobes p (verdict) "
              + "".join(f"| Mitsuba ires {r}: rel L1 | max dev/σ " for r in args.ires) + "|")
        print("|---|---|---|---" + "|---|---" * len(args.ires) + "|")
        for row in rows:
            cells = ""
            for r in args.ires:
                c = row["expected_vs_lobes"][str(r)]
                cells += f"| {fmt(c and c['rel_l1'], '.2e')} | {fmt(c and c['max_sigma'], '.3g')} "
            print(f"| {row['lobe']} | {row['method']} | {row['mitsuba_p_value']:.3g} "
                  f"({'pass' if row['mitsuba_passed'] else 'FAIL'}) | {row['lobes_p_value']:.3g} "
                  f"({'pass' if row['lobes_passed'] else 'FAIL'}) " + cells + "|")
        if "probe" in l:
            m_sps = args.samples / results[("ggx", "ndf", "mitsuba", i0)]["hist_seconds"]
            l_sps = l["bench"][("ggx", "ndf")]["samples_per_second"]
            print()
            print("The kernel ceiling (bench/probe; GGX NDF, 2^24 samples, median of %d): plain kernels against "
                  "Mitsuba's GGX NDF sampling + histogram in this run." % max(args.runs, 5))
            print()
            print("| kernel | samples/s | / Mitsuba GGX NDF |")
            print("|---|---|---|")
            print(f"| Mitsuba {mi.__version__} GGX NDF (sample + histogram) | {m_sps:.3g} | 1 |")
            print(f"| lobes GGX NDF (sample + histogram) | {l_sps:.3g} | {l_sps / m_sps:.2f} |")
            for name, what in PROBE_VARIANTS:
                print(f"| probe {name}: {what} | {l['probe'][name]:.3g} | {l['probe'][name] / m_sps:.2f} |")
        out_drivers.append({"label": l["label"], "probe": l.get("probe"), "lobes_adapter": l["adapter"], "mesa": l["mesa"], "rows": rows,
                            "lobes_batch": l["batch"]})

    print()
    print("Whole batch: the 4 cases (alpha %g, theta_i %g deg, 2^%g samples, %d x %d bins), each tool as ONE process "
          "from start to verdicts, warm caches; median of %d runs (min-max). Mitsuba: import + 4 x "
          "ChiSquareTest(res=%d, ires=%d).run(). Ratio > 1: lobes faster."
          % (args.alpha, args.batch_incident_theta, math.log2(args.samples), args.res, args.res // 2, args.runs,
             args.res, BATCH_IRES))
    print()
    print("| process | Mesa | seconds | min-max | verdicts | Mitsuba s / lobes s |")
    print("|---|---|---|---|---|---|")
    mb = mitsuba_batch
    print(f"| Mitsuba {mi.__version__} {mi.variant()} | - | {mb['seconds']:.3f} | {min(mb['all']):.3f}-{max(mb['all']):.3f} "
          f"| {mb['verdicts']} | 1 |")
    for l in lobes:
        b = l["batch"]
        print(f"| lobes run | {l['mesa']} | {b['seconds']:.3f} | {min(b['all']):.3f}-{max(b['all']):.3f} "
              f"| {b['verdicts']} | {mb['seconds'] / b['seconds']:.2f} |")

    if args.json:
        with open(args.json, "w") as f:
            json.dump({"samples": args.samples, "alpha": args.alpha,
                       "incident_theta": args.incident_theta, "incident_phi": args.incident_phi,
                       "batch_incident_theta": args.batch_incident_theta, "batch_ires": BATCH_IRES,
                       "runs": args.runs, "res": args.res, "ires": args.ires,
                       "variant": mi.variant(), "mitsuba": mi.__version__, "drjit": dr.__version__,
                       "drjit_libllvm_path": os.environ.get("DRJIT_LIBLLVM_PATH"),
                       "lobes": args.lobes, "mitsuba_batch": mitsuba_batch, "drivers": out_drivers}, f, indent=1)


if __name__ == "__main__":
    main()
