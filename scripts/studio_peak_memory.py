#!/usr/bin/env python3
"""Peak memory of `toonkit studio` while it refuses over-budget requests, and while requests
each under the job budget run at once (its memory pool: the excess is answered 503).

Starts `toonkit studio FILE --port 0 --no-open` under `ulimit -v` (default 4 GiB), prepares
the clip once, then for each request resets the peak (`/proc/PID/clear_refs` 5), sends it,
reads `VmHWM` from `/proc/PID/status` and checks that the next request is answered. Prints a
Markdown table (docs/studio-budgets.md holds the figures measured with it).

Usage: scripts/studio_peak_memory.py [--toonkit target/release/toonkit]
       [--file assets/characters/RobotExpressive.glb] [--clip Wave] [--limit-gib 4]
       [--concurrent 8] [--lines 20000] [--job-bytes 2e9]
Python standard library only; Linux only (/proc).
"""

import argparse
import http.client
import json
import os
import subprocess
import sys
import tempfile
import threading
import time


def studio_start(toonkit, path, out, limit_kib, job_bytes):
    env = dict(os.environ)
    if job_bytes:
        env["TOONKIT_MAX_JOB_BYTES"] = job_bytes
    script = f"ulimit -v {limit_kib} && exec '{toonkit}' studio '{path}' --port 0 --no-open --out '{out}'"
    child = subprocess.Popen(["sh", "-c", script], stdout=subprocess.PIPE,
                             stderr=subprocess.DEVNULL, env=env, text=True)
    line = child.stdout.readline()
    if "127.0.0.1:" not in line:
        child.kill()
        sys.exit(f"the studio did not start: {line!r}")
    port = int(line.split("127.0.0.1:")[1].split("/")[0])
    return child, port


def request(port, method, path, body=None, timeout=600):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
    data = None if body is None else (body if isinstance(body, bytes) else json.dumps(body).encode())
    headers = {"Host": f"127.0.0.1:{port}", "Content-Type": "application/json"}
    try:
        c.request(method, path, body=data, headers=headers)
        r = c.getresponse()
        payload = r.read()
        return r.status, payload
    except (ConnectionError, http.client.HTTPException) as e:
        return 0, str(e).encode()
    finally:
        c.close()


def status_mib(pid, key):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith(key):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def reset_peak(pid):
    with open(f"/proc/{pid}/clear_refs", "w") as f:
        f.write("5")


def error_of(payload):
    try:
        return json.loads(payload)["error"]
    except (ValueError, KeyError, TypeError):
        return payload[:80].decode(errors="replace")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--toonkit", default="target/release/toonkit")
    ap.add_argument("--file", default="assets/characters/RobotExpressive.glb")
    ap.add_argument("--clip", default="Wave")
    ap.add_argument("--limit-gib", type=float, default=4.0)
    ap.add_argument("--concurrent", type=int, default=8)
    ap.add_argument("--lines", type=int, default=20000,
                    help="motion lines of each concurrent request (under the budget)")
    ap.add_argument("--skip", action="append", default=[],
                    help="leave out the refusals whose name holds this text")
    ap.add_argument("--no-concurrent", action="store_true")
    ap.add_argument("--job-bytes", default="",
                    help="TOONKIT_MAX_JOB_BYTES for the studio (default: half the limit)")
    a = ap.parse_args()
    limit_kib = int(a.limit_gib * (1 << 20))
    out = tempfile.mkdtemp(prefix="studio-peak-")
    child, port = studio_start(a.toonkit, a.file, out, limit_kib, a.job_bytes)
    pid = child.pid  # `exec` keeps the shell's pid
    try:
        status, _ = request(port, "GET", f"/api/smear/offsets?clip={a.clip}")
        assert status == 200, status
        print(f"studio under ulimit -v {a.limit_gib:g} GiB, {a.file} ({a.clip} prepared): "
              f"{status_mib(pid, 'VmRSS:'):.0f} MiB resident\n")
        style = lambda toml: {"clip": a.clip, "toml": toml}
        stroke = [[10.0, 10.0], [20.0, 40.0], [30.0, 80.0]]
        many_keys = [{"frame": k, "points": [[10.0, 10.0], [20.0, 40.0 + k % 7]]} for k in range(10_000)]
        far_keys = [{"frame": 0, "points": stroke}, {"frame": 10**9, "points": stroke}]
        long_expr = "delta" + " + delta" * 150_000
        refusals = [
            ("10^7 motion lines", "POST", "/api/smear/stylize", style("[lines]\ncount = 10000000\n")),
            ("10,000 keystrokes", "POST", "/api/loa/animate",
             {"keystrokes": many_keys, "width": 800, "height": 600}),
            ("2 keystrokes 10^9 frames apart", "POST", "/api/loa/animate",
             {"keystrokes": far_keys, "width": 800, "height": 600}),
            ("smoothing 10^9 frames", "POST", "/api/smear/stylize",
             style("[offsets]\nsmooth = 1000000000\n[elongate]\n")),
            ("a 1.2 MB expression", "POST", "/api/smear/stylize",
             style(f'[elongate]\nfunction = {{ expr = "{long_expr}" }}\n')),
            ("a 3 MB body", "POST", "/api/smear/stylize", b"{" + b" " * (3 << 20) + b"}"),
            ("a 100 MB body", "POST", "/api/loa/animate", b"[" + b"0," * (50 << 20) + b"0]"),
        ]
        print("| request | body bytes | HTTP | RSS before (MiB) | peak (MiB) | next request |")
        print("|---|---:|---:|---:|---:|---:|")
        for what, method, path, body in refusals:
            if any(k in what for k in a.skip):
                continue
            data = body if isinstance(body, bytes) else json.dumps(body).encode()
            reset_peak(pid)
            before = status_mib(pid, "VmRSS:")
            status, payload = request(port, method, path, data)
            peak = status_mib(pid, "VmHWM:")
            nxt, _ = request(port, "GET", "/api/info")
            print(f"| {what} | {len(data)} | {status} | {before:.0f} | {peak:.0f} | {nxt} |")
            print(f"|  ↳ {error_of(payload)[:150]} | | | | | |")

        if a.no_concurrent:
            return
        # Requests each under the budget, at once: the pool admits what fits, 503 for the rest.
        heavy = json.dumps(style(f"[elongate]\n[lines]\ncount = {a.lines}\n")).encode()
        reset_peak(pid)
        t = time.time()
        status, payload = request(port, "POST", "/api/smear/stylize", heavy)
        one = time.time() - t
        one_peak = status_mib(pid, "VmHWM:")
        print(f"\none request of {a.lines} motion lines alone: HTTP {status}, {one:.2f} s, "
              f"peak {one_peak:.0f} MiB{'' if status == 200 else ': ' + error_of(payload)}")
        answers = []
        reset_peak(pid)

        def send():
            s, p = request(port, "POST", "/api/smear/stylize", heavy)
            answers.append((s, error_of(p) if s != 200 else ""))

        threads = [threading.Thread(target=send) for _ in range(a.concurrent)]
        for th in threads:
            th.start()
        for th in threads:
            th.join()
        peak = status_mib(pid, "VmHWM:")
        codes = sorted(s for s, _ in answers)
        print(f"{a.concurrent} at once: HTTP {codes}, peak {peak:.0f} MiB")
        for s, e in answers:
            if s != 200:
                print(f"  ↳ {e[:200]}")
                break
        nxt, _ = request(port, "POST", "/api/smear/stylize", heavy)
        print(f"the next request: HTTP {nxt}")
    finally:
        child.kill()
        child.wait()


if __name__ == "__main__":
    main()
