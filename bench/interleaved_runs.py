#!/usr/bin/env python3
"""Wall time of whole lobes processes for several builds, runs interleaved so that a machine's
changing load falls on all of them alike; one untimed round first (warm caches). Medians, and
each build's median over the first build's.

  python3 bench/interleaved_runs.py RUNS SCENE NAME=BINARY ... [-- ARGS FOR lobes run]
  python3 bench/interleaved_runs.py RUNS check NAME=BINARY ... -- ARGS FOR lobes check

e.g. python3 bench/interleaved_runs.py 5 bench/batch4.toml before=/tmp/lobes-before after=target/release/lobes
     python3 bench/interleaved_runs.py 5 check before=/tmp/lobes-before after=target/release/lobes -- \\
         examples/samplers/ggx_vndf.wgsl --sample ggx_sample --pdf ggx_pdf --params 0.3,0.3
A BINARY may be a script that sets an environment and runs lobes with "$@". `lobes check` runs
with --json, whose GPU seconds (timestamp queries, where the adapter has them) are reported too.
"""
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time


def command(binary, scene, extra, out):
    if scene == "check":
        return [binary, "check", "--json"] + extra
    return [binary, "run", scene, "--out", out] + extra


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    runs, scene, rest = int(sys.argv[1]), sys.argv[2], sys.argv[3:]
    extra = []
    if "--" in rest:
        i = rest.index("--")
        rest, extra = rest[:i], rest[i + 1:]
    builds = [a.split("=", 1) for a in rest]
    times = {name: [] for name, _ in builds}
    gpu = {name: [] for name, _ in builds}
    with tempfile.TemporaryDirectory(prefix="lobes-interleaved-") as wd:
        for r in range(runs + 1):
            for name, binary in builds:
                t0 = time.perf_counter()
                p = subprocess.run(command(binary, scene, extra, os.path.join(wd, name)), capture_output=True)
                dt = time.perf_counter() - t0
                # exit 1 is a finished run or check with a failed verdict (a broken sampler's)
                if p.returncode not in (0, 1):
                    sys.exit(f"{name}: exit {p.returncode}\n{p.stderr.decode()}")
                if r > 0:
                    times[name].append(dt)
                    seconds = json.loads(p.stdout).get("gpu_seconds") if scene == "check" else None
                    if seconds is not None:
                        gpu[name].append(seconds)
    first = statistics.median(times[builds[0][0]])
    print(f"load average {os.getloadavg()[0]:.1f}")
    for n, v in times.items():
        g = f"; GPU {statistics.median(gpu[n]):.3f} s" if gpu[n] else ""
        print(f"{n}: median {statistics.median(v):.3f} s (min {min(v):.3f}, max {max(v):.3f}; "
              f"{statistics.median(v) / first:.3f} of {builds[0][0]}){g}")


if __name__ == "__main__":
    main()
