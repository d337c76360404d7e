#!/usr/bin/env python3
"""Issue 25's panel of subtly broken samplers as a benchmark, lobes and Mitsuba 3 in one run.

The panel (tests/fixtures/family/broken_*.wgsl, each with a correct twin):

  turn     GGX visible normals (alpha 0.3, theta_i 30 deg) turned about the normal by
           0.005 sin(phi), the pdf unchanged (density ~0.5 % cos(phi) off)
  radial   a cosine-weighted lobe whose radial uniform is warped u -> u + 0.005 u (1 - u)
  share    GGX (alpha 0.3) + diffuse mixture, w = 1/2, choosing GGX with w + 0.003
  grazing  a uniform hemisphere turned by 0.008 sin(phi) at theta > 72.5 deg only

lobes: `lobes check FILES --sample S --pdf P --params ... --samples N --seed SEED --json`
(the default settings otherwise: 64 x 128 bins, significance 0.01, theta_i 30 deg). For
each broken sampler, a doubling search over N = 2^first .. 2^last with every seed of
--seeds: the smallest N at which every seed's 64 x 128 grid alone rejects (p < 0.01, the
test before issue 25) and at which every seed's family of tests rejects (the chi2 check
fails). The search stops once both are found (or at 2^last). The seconds to a verdict are
the wall time of the whole `lobes check` process at that N (every check, start-up
included), the median of the seeds' runs and --runs - len(seeds) more runs of the first
seed. At the family's N the correct twin is run with the same seeds: a correct verdict
needs it to pass.

Mitsuba 3: the same four defects and twins written here in Dr.Jit (the same maths as the
WGSL files), through mitsuba.chi2.ChiSquareTest(SphericalDomain(), ..., sample_dim=3,
sample_count=N, res=101, ires=4, seed=SEED).run(0.01): its defaults but for the sample
count and seed. Every N of the same doubling and every seed, for each defect and its twin,
so the table shows from which N each defect is caught and from which N the correct twin
is falsely rejected. Seconds: construct + run() of one test after an untimed warm-up
(Dr.Jit compiles its kernels on first use), the median over the seeds.

False-alarm battery: every shipped correct sampler (examples/samplers/*.wgsl that are not
broken_*; the mixture also at w = 0, the panel's diffuse twin) and the grazing twin
(bench/panel/uniform_hemisphere.wgsl) x --battery-seeds at lobes check's defaults
(2^22 samples), and the Mitsuba twins x the same seeds at 2^22: the number rejected
against the most that chance allows at significance 0.01 (binomial, P(more) < 1e-3).

This is a tool of the repository, not a dependency of the crate; set-up in bench/README.md.
"""

import argparse
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EX = "examples/samplers/"
FX = "tests/fixtures/family/"
SIGNIFICANCE = 0.01  # lobes check's default --significance, and Mitsuba's run() default

# name, defect, (files, sample, pdf, params) broken, (...) correct twin
PANEL = [
    ("turn", "azimuthal turn 0.005 sin φ (GGX VNDF α 0.3, θi 30°)",
     ([EX + "ggx_vndf.wgsl", "src/experiments/tradeoff/turn.wgsl"], "turn_sample", "turn_pdf", "0.3,0.3,0.005"),
     ([EX + "ggx_vndf.wgsl"], "ggx_sample", "ggx_pdf", "0.3,0.3")),
    ("radial", "radial warp 0.5 % (cosine-weighted)",
     ([FX + "broken_radial_warp.wgsl"], "radial_sample", "radial_pdf", None),
     ([EX + "ggx_vndf.wgsl", EX + "ggx_diffuse_mixture.wgsl"], "mix_sample", "mix_pdf", "0.3,0.3,0")),
    ("share", "mixture share +0.003 (GGX α 0.3 + diffuse, w ½)",
     ([EX + "ggx_vndf.wgsl", EX + "ggx_diffuse_mixture.wgsl", FX + "broken_mixture_share.wgsl"],
      "share_sample", "share_pdf", "0.3,0.3,0.5"),
     ([EX + "ggx_vndf.wgsl", EX + "ggx_diffuse_mixture.wgsl"], "mix_sample", "mix_pdf", "0.3,0.3,0.5")),
    ("grazing", "grazing turn 0.008 sin φ at θ > 72.5° (uniform hemisphere)",
     ([FX + "broken_grazing_turn.wgsl"], "grazing_sample", "grazing_pdf", None),
     (["bench/panel/uniform_hemisphere.wgsl"], "uniform_sample", "uniform_pdf", None)),
]

# every shipped correct sampler at lobes check's defaults (as tests/family.rs's battery)
BATTERY = [
    ("ggx_vndf α 0.3", [EX + "ggx_vndf.wgsl"], "ggx_sample", "ggx_pdf", "0.3,0.3", []),
    ("diffuse (mixture w 0)", [EX + "ggx_vndf.wgsl", EX + "ggx_diffuse_mixture.wgsl"], "mix_sample", "mix_pdf", "0.3,0.3,0", []),
    ("ggx_diffuse_mixture w ½", [EX + "ggx_vndf.wgsl", EX + "ggx_diffuse_mixture.wgsl"], "mix_sample", "mix_pdf", "0.3,0.3,0.5", []),
    ("beckmann_vndf α 0.5", [EX + "beckmann_vndf.wgsl"], "beck_sample", "beck_pdf", "0.5,0.5", []),
    ("henyey_greenstein g 0.7", [EX + "henyey_greenstein.wgsl"], "hg_sample", "hg_pdf", "0.7", []),
    ("rough_dielectric α 0.3 η 1.5", [EX + "ggx_vndf.wgsl", EX + "rough_dielectric.wgsl"], "rd_sample", "rd_pdf", "0.3,0.3,1.5", []),
    ("piecewise_2d (plane)", [EX + "piecewise_2d.wgsl"], "env_sample", "env_pdf", None, ["--domain", "plane", "--bounds", "0,0,1,1"]),
    ("uniform hemisphere (bench/panel)", ["bench/panel/uniform_hemisphere.wgsl"], "uniform_sample", "uniform_pdf", None, []),
]


def die(msg):
    print(f"family_panel.py: error: {msg}", file=sys.stderr)
    sys.exit(2)


def int_list(text):
    try:
        xs = [int(x) for x in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: expected comma-separated integers, e.g. 1,2") from None
    if not xs or min(xs) < 0:
        raise argparse.ArgumentTypeError(f"{text!r}: expected non-negative integers")
    return xs


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def ps(xs):
    return "[" + ", ".join(f"{x:.1e}" for x in xs) + "]"


def binomial_tail(n, p, k):
    """P(X > k) for X ~ Binomial(n, p)."""
    return max(0.0, 1.0 - sum(math.comb(n, i) * p**i * (1 - p) ** (n - i) for i in range(k + 1)))


def chance_limit(n, p=SIGNIFICANCE):
    return next(k for k in range(n + 1) if binomial_tail(n, p, k) < 1e-3)


# ---------------------------------------------------------------- lobes


def lobes_check(lobes, spec, samples, seed, extra=()):
    files, sample, pdf, params = spec
    cmd = [lobes, "check", *files, "--sample", sample, "--pdf", pdf, "--samples", str(samples),
           "--seed", str(seed), "--json", *extra]
    if params:
        cmd += ["--params", params]
    t0 = time.perf_counter()
    out = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if out.returncode not in (0, 1):
        die(f"`{' '.join(cmd)}` exited with {out.returncode}:\n{out.stderr}")
    rep = json.loads(out.stdout)
    chi2 = next(c for c in rep["checks"] if c["name"] == "chi2")["figures"]
    caught = [t["test"] for t in chi2.get("family", []) if t["rejected"]]
    return {
        "samples": samples, "seed": seed, "wall_seconds": wall, "adapter": rep.get("adapter"),
        "fine_p": chi2["p_value"], "fine_rejects": chi2["p_value"] < chi2["significance"],
        "family_p": chi2.get("family_p_value"), "family_rejects": not chi2["passed"],
        "caught_by": caught,
        "other_failed": [c["name"] for c in rep["checks"] if not c["passed"] and c["name"] != "chi2"],
    }


def lobes_search(args, name, broken, twin):
    found = {"fine": None, "family": None, "last": None, "steps": []}
    for k in range(args.first, args.last + 1):
        runs = [lobes_check(args.lobes, broken, 1 << k, s) for s in args.seeds]
        found["steps"].append(runs)
        found["last"] = k
        log(f"lobes {name} 2^{k}: fine p {ps(r['fine_p'] for r in runs)}, family p "
            f"{ps(r['family_p'] for r in runs)}, caught by {[r['caught_by'] for r in runs]}"
            f"{', other checks failed ' + str([r['other_failed'] for r in runs]) if any(r['other_failed'] for r in runs) else ''}")
        for key, flag in (("fine", "fine_rejects"), ("family", "family_rejects")):
            if found[key] is None and all(r[flag] for r in runs):
                extra = [lobes_check(args.lobes, broken, 1 << k, args.seeds[0])
                         for _ in range(max(0, args.runs - len(runs)))]
                found[key] = {"log2": k, "seconds": statistics.median(r["wall_seconds"] for r in runs + extra),
                              "timed_runs": len(runs + extra), "caught_by": [r["caught_by"] for r in runs]}
                if key == "family":
                    tw = [lobes_check(args.lobes, twin, 1 << k, s) for s in args.seeds]
                    found[key]["twin_rejected"] = sum(r["family_rejects"] for r in tw)
                    found[key]["twin_family_p"] = [r["family_p"] for r in tw]
                if key == "fine":
                    found[key]["family_also"] = all(r["family_rejects"] for r in runs)
        if found["fine"] is not None and found["family"] is not None:
            break
    return found


def lobes_battery(args):
    rows, fam, fine = [], 0, 0
    for name, files, sample, pdf, params, extra in BATTERY:
        for s in args.battery_seeds:
            r = lobes_check(args.lobes, (files, sample, pdf, params), 1 << 22, s, extra)
            fam += r["family_rejects"]
            fine += r["fine_rejects"]
            rows.append({"sampler": name, **r})
            log(f"lobes battery {name} seed {s}: fine p {r['fine_p']:.3f}, family p {r['family_p']:.3f}"
                f"{', REJECTED by ' + str(r['caught_by']) if r['family_rejects'] else ''}"
                f"{', other checks failed ' + str(r['other_failed']) if r['other_failed'] else ''}")
    return {"runs": len(rows), "family_rejected": fam, "fine_rejected": fine, "rows": rows,
            "smallest_family_p": min(r["family_p"] for r in rows),
            "other_failed": sum(bool(r["other_failed"]) for r in rows)}


# ---------------------------------------------------------------- Mitsuba


def import_mitsuba(variant):
    if variant.startswith("llvm") and not os.environ.get("DRJIT_LIBLLVM_PATH"):
        for cand in ("/usr/lib/x86_64-linux-gnu/libLLVM-19.so", "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1"):
            if os.path.exists(cand):
                os.environ["DRJIT_LIBLLVM_PATH"] = cand
                log(f"# DRJIT_LIBLLVM_PATH not set; using {cand}")
                break
    try:
        import drjit as dr
        import mitsuba as mi
    except ImportError as e:
        die(f"cannot import Mitsuba 3 ({e}).\n  Install it with: pip install mitsuba==3.9.1 drjit==1.5.0 and Debian's "
            "libllvm19 (bench/README.md), or pass --no-mitsuba.")
    try:
        mi.set_variant(variant)
        _ = float(dr.sum(mi.Float([1.0, 2.0]))[0])  # start the backend now: a broken LLVM fails here
    except Exception as e:  # noqa: BLE001
        die(f"Mitsuba variant {variant!r} does not work here: {e}\n  DRJIT_LIBLLVM_PATH="
            f"{os.environ.get('DRJIT_LIBLLVM_PATH')!r}; Debian 12's LLVM 15 fails ('Cannot select fmaximum'), use libllvm19.")
    import mitsuba.chi2 as chi2
    return mi, dr, chi2


def mitsuba_samplers(mi, dr):
    """The panel in Dr.Jit: each entry name -> (broken, twin), each a (sample, pdf) pair for
    ChiSquareTest with sample_dim 3: u = (x, y, event) as lobes' u.x, u.y, u.z."""
    pi = math.pi
    ti = math.radians(30.0)
    wi = (math.sin(ti), 0.0, math.cos(ti))  # theta_i 30 deg, phi_i 0: lobes check's default
    a = 0.3

    def V(x, y, z):
        return mi.Vector3f(x, y, z)

    # GGX by visible normals (Heitz 2018): the stretched view direction and its frame are constants
    vh = (a * wi[0], a * wi[1], wi[2])
    n = math.sqrt(sum(c * c for c in vh))
    vh = tuple(c / n for c in vh)
    lensq = vh[0] ** 2 + vh[1] ** 2
    t1 = (-vh[1] / math.sqrt(lensq), vh[0] / math.sqrt(lensq), 0.0) if lensq > 0 else (1.0, 0.0, 0.0)
    t2 = (vh[1] * t1[2] - vh[2] * t1[1], vh[2] * t1[0] - vh[0] * t1[2], vh[0] * t1[1] - vh[1] * t1[0])
    lam = 0.5 * (-1.0 + math.sqrt(1.0 + a * a * (wi[0] ** 2 + wi[1] ** 2) / wi[2] ** 2))
    g1 = 1.0 / (1.0 + lam)

    def ggx_sample(u):
        r = dr.sqrt(u.x)
        s_phi, c_phi = dr.sincos(2 * pi * u.y)
        p1 = r * c_phi
        s = 0.5 * (1.0 + vh[2])
        p2 = (1.0 - s) * dr.safe_sqrt(1.0 - p1 * p1) + s * r * s_phi
        p3 = dr.safe_sqrt(1.0 - p1 * p1 - p2 * p2)
        nh = [p1 * t1[i] + p2 * t2[i] + p3 * vh[i] for i in range(3)]
        h = dr.normalize(V(a * nh[0], a * nh[1], dr.maximum(0.0, nh[2])))
        k = 2.0 * (wi[0] * h.x + wi[1] * h.y + wi[2] * h.z)
        return V(k * h.x - wi[0], k * h.y - wi[1], k * h.z - wi[2])

    def ggx_pdf(d):
        m = V(d.x + wi[0], d.y + wi[1], d.z + wi[2])
        len2 = dr.squared_norm(m)
        h = m / dr.sqrt(dr.maximum(len2, 1e-30))
        t = (h.x * h.x + h.y * h.y) / (a * a) + h.z * h.z
        D = 1.0 / (pi * a * a * t * t)
        ok = (len2 > 0) & (wi[0] * h.x + wi[1] * h.y + wi[2] * h.z > 0) & (h.z > 0)
        return dr.select(ok, g1 * D / (4.0 * wi[2]), 0.0)

    def turned(d, t):
        s, c = dr.sincos(t)
        return V(c * d.x - s * d.y, s * d.x + c * d.y, d.z)

    def weighted(sample, pdf):
        def f(u):
            d = sample(u)
            return d, dr.select(pdf(d) > 0, 1.0, 0.0)
        return f, pdf

    # 1. the turn: phi -> phi + eps sin(phi), pdf unchanged
    def turn(eps):
        def sample(u):
            d = ggx_sample(u)
            return turned(d, eps * dr.sin(dr.atan2(d.y, d.x)))
        return weighted(sample, ggx_pdf)

    # 2. cosine-weighted (Malley) with the radial uniform warped u -> u + eps u (1 - u)
    def diffuse_pdf(d):
        return dr.maximum(0.0, d.z) / pi

    def diffuse_dir(ux, uy, eps):
        v = ux + eps * ux * (1.0 - ux)
        r = dr.sqrt(v)
        s, c = dr.sincos(2 * pi * uy)
        return V(r * c, r * s, dr.safe_sqrt(1.0 - v))

    def radial(eps):
        return weighted(lambda u: diffuse_dir(u.x, u.y, eps), diffuse_pdf)

    # 3. the mixture choosing GGX with w + delta while its pdf weighs GGX by w
    w = 0.5

    def mix_pdf(d):
        return w * ggx_pdf(d) + (1.0 - w) * diffuse_pdf(d)

    def share(delta):
        def sample(u):
            g = ggx_sample(u)
            f = diffuse_dir(u.x, u.y, 0.0)
            return dr.select(u.z < w + delta, g, f)
        return weighted(sample, mix_pdf)

    # 4. uniform hemisphere, turned by eps (1 - smoothstep(0.15, 0.3, cos theta)) sin(phi)
    def uniform_pdf(d):
        return dr.select(d.z > 0, 0.5 / pi, 0.0)

    def grazing(eps):
        def sample(u):
            z = u.x
            r = dr.safe_sqrt(1.0 - z * z)
            phi = 2 * pi * u.y - pi
            t = dr.clip((z - 0.15) / 0.15, 0.0, 1.0)
            phi2 = phi + eps * (1.0 - t * t * (3.0 - 2.0 * t)) * dr.sin(phi)
            s, c = dr.sincos(phi2)
            return V(r * c, r * s, z)
        return weighted(sample, uniform_pdf)

    return {
        "turn": (turn(0.005), turn(0.0)),
        "radial": (radial(0.005), radial(0.0)),
        "share": (share(0.003), share(0.0)),
        "grazing": (grazing(0.008), grazing(0.0)),
    }


def mitsuba_test(mi, dr, chi2, sp, samples, seed, res, ires):
    sample, pdf = sp
    t0 = time.perf_counter()
    t = chi2.ChiSquareTest(chi2.SphericalDomain(), sample, pdf, sample_dim=3, sample_count=samples,
                           res=res, ires=ires, seed=seed)
    ok = t.run(SIGNIFICANCE, quiet=True)
    return {"samples": samples, "seed": seed, "rejects": not ok, "p": float(t.p_value) if t.p_value is not None else None,
            "seconds": time.perf_counter() - t0, "messages": t.messages.strip().splitlines()[-1:] if not ok else []}


def mitsuba_panel(args, mi, dr, chi2, ires):
    samplers = {k: v for k, v in mitsuba_samplers(mi, dr).items() if k in args.names}
    out = {}
    for name, (broken, twin) in samplers.items():
        for sp in (broken, twin):  # warm-up: Dr.Jit compiles each kernel on first use
            mitsuba_test(mi, dr, chi2, sp, 1 << args.first, 0, args.res, ires)
        steps, caught, twin_fails = [], None, None
        for k in range(args.first, min(args.last, args.mitsuba_last) + 1):
            b = [mitsuba_test(mi, dr, chi2, broken, 1 << k, s, args.res, ires) for s in args.seeds]
            c = [mitsuba_test(mi, dr, chi2, twin, 1 << k, s, args.res, ires) for s in args.seeds]
            steps.append({"log2": k, "broken": b, "twin": c})
            log(f"mitsuba ires {ires} {name} 2^{k}: broken p {ps(r['p'] for r in b)}, twin p {ps(r['p'] for r in c)}")
            if caught is None and all(r["rejects"] for r in b):
                caught = {"log2": k, "seconds": statistics.median(r["seconds"] for r in b),
                          "twin_rejected": sum(r["rejects"] for r in c)}
            if twin_fails is None and any(r["rejects"] for r in c):
                twin_fails = {"log2": k, "seeds_rejected": sum(r["rejects"] for r in c)}
        out[name] = {"caught": caught, "twin_first_false_alarm": twin_fails,
                     "last": min(args.last, args.mitsuba_last), "steps": steps}
    battery = [mitsuba_test(mi, dr, chi2, twin, 1 << 22, s, args.res, ires)
               for name, (_, twin) in samplers.items() for s in args.battery_seeds]
    out["battery"] = {"runs": len(battery), "rejected": sum(r["rejects"] for r in battery),
                      "smallest_p": min(r["p"] for r in battery)}
    return out


# ---------------------------------------------------------------- tables


def pow2(k, last):
    return f"2^{k}" if k is not None else f"> 2^{last}"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--lobes", default=os.path.join(ROOT, "target/release/lobes"))
    ap.add_argument("--seeds", type=int_list, default=[1, 2], help="seeds of the doubling search (all must reject)")
    ap.add_argument("--battery-seeds", type=int_list, default=[1, 2, 3, 4])
    ap.add_argument("--first", type=int, default=18, help="log2 of the search's first count")
    ap.add_argument("--last", type=int, default=27, help="log2 of the search's last count")
    ap.add_argument("--mitsuba-last", type=int, default=27, help="log2 of Mitsuba's last count")
    ap.add_argument("--runs", type=int, default=3, help="timed runs per lobes verdict (median)")
    ap.add_argument("--only", help="comma-separated panel names (turn, radial, share, grazing)")
    ap.add_argument("--no-mitsuba", action="store_true")
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--res", type=int, default=101)
    ap.add_argument("--ires", type=int, nargs="+", default=[4],
                    help="Mitsuba's trapezoid points per cell side; each value is a separate pass (4: its default)")
    ap.add_argument("--json", help="write every measurement here")
    args = ap.parse_args()
    names = [p[0] for p in PANEL]
    unknown = [n for n in (args.only or "").split(",") if args.only and n not in names]
    if unknown:
        die(f"--only {args.only}: unknown {unknown}; the panel is {','.join(names)}")
    if not 0 <= args.first <= args.last <= 40:
        die(f"--first {args.first} --last {args.last}: need 0 <= first <= last <= 40 (log2 of the counts)")
    panel = [p for p in PANEL if not args.only or p[0] in args.only.split(",")]
    args.names = [p[0] for p in panel]
    if not os.path.exists(args.lobes):
        die(f"no lobes binary at {args.lobes} (cargo build --release, or --lobes PATH)")
    mi = dr = chi2 = None
    if not args.no_mitsuba:
        mi, dr, chi2 = import_mitsuba(args.variant)
    t_start = time.perf_counter()
    lobes = {name: lobes_search(args, name, broken, twin) for name, _, broken, twin in panel}
    battery = lobes_battery(args)
    adapter = battery["rows"][0]["adapter"]
    mits = {ires: mitsuba_panel(args, mi, dr, chi2, ires) for ires in args.ires} if mi else None

    print(f"# lobes {adapter}; {platform.machine()}, {os.cpu_count()} CPUs, Python {platform.python_version()}"
          + (f"; Mitsuba {mi.__version__} ({mi.variant()}, res {args.res}, ires {args.ires})" if mi else ""))
    print(f"# seeds {args.seeds} (every seed must reject), N = 2^{args.first} .. 2^{args.last}, "
          f"significance {SIGNIFICANCE}; whole run {time.perf_counter() - t_start:.0f} s\n")
    print("| defect | lobes 64 × 128 alone | s | lobes family | s | caught by (per seed) | twin rejected there |\n"
          "|---|---|---|---|---|---|---|")
    for name, defect, _, _ in panel:
        f = lobes[name]
        fine, fam = f["fine"], f["family"]
        row = (f"| {defect} | {pow2(fine['log2'], f['last'])} | {fine['seconds']:.1f} |" if fine else
               f"| {defect} | {pow2(None, f['last'])} | – |")
        row += (f" {pow2(fam['log2'], f['last'])} | {fam['seconds']:.1f} | "
                f"{' / '.join(', '.join(c) for c in fam['caught_by'])} | {fam['twin_rejected']} of {len(args.seeds)} |"
                if fam else f" {pow2(None, f['last'])} | – | – | – |")
        print(row)
    for ires, m_all in (mits or {}).items():
        print(f"\n| defect | Mitsuba res {args.res} ires {ires} catches | s | its twin rejected there | its twin first rejected |\n"
              "|---|---|---|---|---|")
        for name, defect, _, _ in panel:
            m = m_all[name]
            c, tf = m["caught"], m["twin_first_false_alarm"]
            row = (f"| {defect} | {pow2(c['log2'], m['last'])} | {c['seconds']:.2f} | {c['twin_rejected']} of {len(args.seeds)} |"
                   if c else f"| {defect} | {pow2(None, m['last'])} | – | – |")
            row += (f" 2^{tf['log2']} ({tf['seeds_rejected']} of {len(args.seeds)}) |" if tf else f" never up to 2^{m['last']} |")
            print(row)
    lim = chance_limit(battery["runs"])
    print(f"\nFalse alarms, lobes check at its defaults (2^22 samples, 64 × 128): {len(BATTERY)} correct samplers × "
          f"seeds {args.battery_seeds} = {battery['runs']} runs: the family rejected {battery['family_rejected']}, "
          f"the 64 × 128 grid alone {battery['fine_rejected']} (chance at 0.01 allows at most {lim}, P(more) < 1e-3); "
          f"smallest family p {battery['smallest_family_p']:.3f}; runs where another check failed: {battery['other_failed']}.")
    for ires, m_all in (mits or {}).items():
        b = m_all["battery"]
        print(f"False alarms, Mitsuba at 2^22 (res {args.res}, ires {ires}): the panel's {len(panel)} correct twins × seeds "
              f"{args.battery_seeds} = {b['runs']} runs: rejected {b['rejected']} (chance allows at most "
              f"{chance_limit(b['runs'])}); smallest p {b['smallest_p']:.3f}.")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"args": {k: v for k, v in vars(args).items()}, "adapter": adapter, "lobes": lobes,
                       "battery": battery, "mitsuba": mits}, fh, indent=1)


if __name__ == "__main__":
    main()
