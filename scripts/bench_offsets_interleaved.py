#!/usr/bin/env python3
"""Whole-process wall time of `toonkit smear offsets` for several builds, run interleaved.

The benchmark VM's speed drifts by a quarter over minutes, so two builds timed one after the
other (as hyperfine does) can differ by more than any change between them. This runs the
builds in turn, run after run, so that drift hits all of them alike, and prints min, first
quartile and median wall time, and the median CPU time (user + system) of each.

usage: scripts/bench_offsets_interleaved.py TUBE.glb RUNS TOONKIT [TOONKIT ...]
(TUBE.glb: `cargo run --release -p toonkit-smear --example write_tube -- TUBE.glb 40`)
"""
import os
import statistics
import sys
import tempfile
import time


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    tube, runs, bins = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
    out = tempfile.mkdtemp()
    null = os.open(os.devnull, os.O_WRONLY)
    quiet = [(os.POSIX_SPAWN_DUP2, null, 1), (os.POSIX_SPAWN_DUP2, null, 2)]

    def run(k):
        args = [bins[k], "smear", "offsets", tube, "-o", os.path.join(out, f"{k}.npy")]
        start = time.perf_counter_ns()
        pid = os.posix_spawn(bins[k], args, os.environ, file_actions=quiet)
        _, status, usage = os.wait4(pid, 0)
        if status != 0:
            sys.exit(f"{bins[k]} failed (status {status})")
        return (time.perf_counter_ns() - start) / 1e6, (usage.ru_utime + usage.ru_stime) * 1e3

    for k in range(len(bins)):
        for _ in range(3):
            run(k)
    wall = [[] for _ in bins]
    cpu = [[] for _ in bins]
    for _ in range(runs):
        for k in range(len(bins)):
            w, c = run(k)
            wall[k].append(w)
            cpu[k].append(c)
    for k, b in enumerate(bins):
        w = sorted(wall[k])
        print(
            f"{b}: min {w[0]:.2f} ms, p25 {w[len(w) // 4]:.2f} ms, "
            f"median {statistics.median(w):.2f} ms, CPU median {statistics.median(cpu[k]):.1f} ms"
        )


if __name__ == "__main__":
    main()
