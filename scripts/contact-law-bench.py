#!/usr/bin/env python3
"""Cost of the contact laws, measured interleaved against a previous binary.

Usage: scripts/contact-law-bench.py OLD_BINARY NEW_BINARY [ROUNDS]

Runs `chocmodal run` on row17 and hex217 (`solver.check: "none"`: the run alone) with
the linear law on both binaries, alternating old and new, and hex217 with friction
(μ = 0.3, k_t = K) on the new one. Prints the median CPU time (user + system, less
noisy than the wall time on a shared machine) of each, the steps, and the ratios. Speed
targets live here, not in tests (docs/contact-laws.md).
"""
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent


def request(name, edit=None):
    body = json.loads((ROOT / "examples" / f"{name}.json").read_text())
    body["inputs"].setdefault("solver", {})["check"] = "none"
    if edit:
        edit(body["inputs"])
    handle = tempfile.NamedTemporaryFile("w", suffix=".json", delete=False)
    json.dump(body, handle)
    handle.close()
    return handle.name


def friction(inputs):
    stiffness = inputs["contact"]["stiffness"]
    inputs["contact"]["law"] = {"friction": {"coefficient": 0.3, "tangential_stiffness": stiffness}}


def run(binary, process, path):
    before = os.times()
    out = subprocess.run([binary, "run", process, path], check=True, capture_output=True, text=True).stdout
    after = os.times()
    seconds = (after.children_user - before.children_user) + (after.children_system - before.children_system)
    return seconds, json.loads(out)["steps"]


def main():
    old, new = sys.argv[1], sys.argv[2]
    rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    cases = [
        ("row17", "bundle-dynamics", request("bundle-row17")),
        ("hex217", "hex-bundle-dynamics", request("hex217")),
    ]
    rubbing = request("hex217", friction)
    times, steps = {}, {}
    for _ in range(rounds):
        for label, process, path in cases:
            for which, binary in (("old", old), ("new", new)):
                seconds, count = run(binary, process, path)
                times.setdefault((label, which), []).append(seconds)
                steps[(label, which)] = count
        seconds, count = run(new, "hex-bundle-dynamics", rubbing)
        times.setdefault(("hex217 friction", "new"), []).append(seconds)
        steps[("hex217 friction", "new")] = count
    best = {key: (statistics.median(values), steps[key]) for key, values in times.items()}
    for label, _, _ in cases:
        (o, so), (n, sn) = best[(label, "old")], best[(label, "new")]
        print(f"{label}, linear law: old {o:.3f} s ({so} steps), new {n:.3f} s ({sn} steps): new/old {n / o:.3f}")
    (n, sn), (f, sf) = best[("hex217", "new")], best[("hex217 friction", "new")]
    print(
        f"hex217 with friction: {f:.3f} s ({sf} steps) against {n:.3f} s ({sn} steps) without: "
        f"run {f / n:.2f}x, per step {(f / sf) / (n / sn):.2f}x"
    )


if __name__ == "__main__":
    main()
