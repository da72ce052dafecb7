#!/usr/bin/python3
"""Ctrl-C latency of the sdfcage program: one uninterrupted run gives the stage timings (from its
JSON report), then SIGINT is sent at N times spread over that run; for each, the time from the
signal to the process's end, its exit code and the stage it fell in. Prints every try and the
worst and median latency per stage. A benchmark (prints figures), not a test.

  cancel_latency.py build/bin/sdfcage ../shared/data/armadillo_midsub4x.obj [--tries 20]
"""
import argparse
import json
import os
import signal
import statistics
import subprocess
import tempfile
import time

STAGES = ["ReadTime", "ValidationTime", "ActivePointTime", "DistanceFieldTime", "IsosurfaceTime",
          "VerificationTime", "SimplificationTime", "CageVerificationTime"]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("cli")
    parser.add_argument("mesh")
    parser.add_argument("--tries", type=int, default=20)
    a = parser.parse_args()
    work = tempfile.mkdtemp(prefix="sdfcage_cancel_")
    report = os.path.join(work, "r.json")
    start = time.monotonic()
    subprocess.run([a.cli, "--quiet", a.mesh, "-o", os.path.join(work, "c.vtp"), "--report", report], check=True)
    total = time.monotonic() - start
    r = json.load(open(report))
    # stage boundaries in wall time: process start-up (until reading starts) is what is left over
    spent = sum(r.get(k, 0.0) for k in STAGES)
    startup = max(0.0, total - spent - r.get("WriteTime", 0.0))
    bounds, t = [("start-up", startup)], startup
    for k in STAGES:
        t += r.get(k, 0.0)
        bounds.append((k.replace("Time", ""), t))
    print(f"uninterrupted run: {total:.2f} s; stages end at " + ", ".join(f"{n} {e:.2f}" for n, e in bounds))

    latencies = {}
    for i in range(a.tries):
        at = total * (i + 0.5) / a.tries
        stage = next((n for n, e in bounds if at <= e), "writing")
        out = os.path.join(work, f"c{i}.vtp")
        p = subprocess.Popen([a.cli, "--quiet", a.mesh, "-o", out], stdout=subprocess.DEVNULL,
                             stderr=subprocess.PIPE)
        time.sleep(at)
        if p.poll() is not None:
            # the run was faster than the uninterrupted one (the machine's load changed): no try
            p.communicate()
            print(f"SIGINT at {at:6.2f} s ({stage:>16}): the run ended first (exit {p.returncode})")
            continue
        sent = time.monotonic()
        p.send_signal(signal.SIGINT)
        p.communicate()
        latency = time.monotonic() - sent
        code = p.returncode if p.returncode >= 0 else 128 - p.returncode
        written = os.path.exists(out)
        print(f"SIGINT at {at:6.2f} s ({stage:>16}): exit {code}, {latency:.3f} s, cage written: {written}")
        latencies.setdefault(stage, []).append(latency)
    print("stage               tries  median   worst")
    for stage, values in latencies.items():
        print(f"{stage:18} {len(values):6} {statistics.median(values):7.3f} {max(values):7.3f}")


if __name__ == "__main__":
    main()
