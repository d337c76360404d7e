#!/usr/bin/env python3
"""Wall time of whole `lobes run` processes for several builds, runs interleaved so that a
machine's changing load falls on all of them alike; one untimed round first (warm caches).

  python3 bench/interleaved_runs.py RUNS SCENE NAME=BINARY ... [-- ARGS FOR lobes run]

e.g. python3 bench/interleaved_runs.py 5 bench/batch4.toml before=/tmp/lobes-before after=target/release/lobes
A BINARY may be a script that sets an environment and runs lobes with "$@".
"""
import os
import statistics
import subprocess
import sys
import tempfile
import time


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
    with tempfile.TemporaryDirectory(prefix="lobes-interleaved-") as wd:
        for r in range(runs + 1):
            for name, binary in builds:
                t0 = time.perf_counter()
                p = subprocess.run([binary, "run", scene, "--out", os.path.join(wd, name)] + extra, capture_output=True)
                dt = time.perf_counter() - t0
                if p.returncode != 0:
                    sys.exit(f"{name}: exit {p.returncode}\n{p.stderr.decode()}")
                if r > 0:
                    times[name].append(dt)
    print(f"load average {os.getloadavg()[0]:.1f}; " + "; ".join(
        f"{n}: median {statistics.median(v):.3f} s (min {min(v):.3f}, max {max(v):.3f})" for n, v in times.items()))


if __name__ == "__main__":
    main()
