#!/usr/bin/env python3
"""Cost of the shipped examples with every solver setting as shipped, interleaved
against a previous binary.

Usage: scripts/check-bench.py OLD_BINARY NEW_BINARY [ROUNDS]

Runs `chocmodal run` on row17 (examples/bundle-row17.json), hex217
(examples/hex217.json) and the public cantilever (examples/cantilever-impact.json), each
as shipped (the step check at its default), alternating old and new binaries. Prints
the median CPU time (user + system) of each, the run's steps, the check's comparison
(`double_step` or `half_step`, new binaries) and its relative cost, the verdict, and the
new/old ratio. Speed targets live here, not in tests (docs/accuracy.md).
"""
import json
import os
import pathlib
import statistics
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
CASES = [
    ("row17", "bundle-dynamics", "bundle-row17"),
    ("hex217", "hex-bundle-dynamics", "hex217"),
    ("cantilever", "cantilever-impact", "cantilever-impact"),
]


def run(binary, process, example):
    path = ROOT / "examples" / f"{example}.json"
    before = os.times()
    out = subprocess.run([binary, "run", process, str(path)], check=True, capture_output=True, text=True).stdout
    after = os.times()
    seconds = (after.children_user - before.children_user) + (after.children_system - before.children_system)
    results = json.loads(out)
    numerical = results.get("numerical", results)
    quality = numerical.get("quality") or results.get("quality") or {}
    check = quality.get("step_halving") or {}
    return seconds, {
        "steps": numerical.get("steps"),
        "check": check.get("compared_with", "half_step" if check else None),
        "check cost": check.get("relative_cost"),
        "verdict": quality.get("verdict"),
    }


def main():
    old, new = sys.argv[1], sys.argv[2]
    rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    times, facts = {}, {}
    for _ in range(rounds):
        for label, process, example in CASES:
            for which, binary in (("old", old), ("new", new)):
                seconds, fact = run(binary, process, example)
                times.setdefault((label, which), []).append(seconds)
                facts[(label, which)] = fact
    for label, _, _ in CASES:
        old_s = statistics.median(times[(label, "old")])
        new_s = statistics.median(times[(label, "new")])
        print(f"{label}: old {old_s:.3f} s {facts[(label, 'old')]}")
        print(f"{label}: new {new_s:.3f} s {facts[(label, 'new')]}")
        print(f"{label}: new/old {new_s / old_s:.2f}")


if __name__ == "__main__":
    main()
