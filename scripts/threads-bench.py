#!/usr/bin/env python3
"""Wall time of the shipped examples on one and on two threads, interleaved, for one
binary or more (the previous one beside the new one).

Usage: scripts/threads-bench.py BINARY [BINARY ...] [--rounds N]

Runs `chocmodal run` on row17 (examples/bundle-row17.json), hex217 (examples/hex217.json),
the same bundle with 61 pins and the public cantilever (examples/cantilever-impact.json),
each as shipped (the step check at its default), hex217 and the same bundle with 61 and
19 pins also with `check: "none"` (their steps shared, nothing to run beside them), with
`solver.threads` 1 and 2, alternating binaries and counts within each round. Prints the median wall and CPU time (user + system) of each and the speed-up
of two threads over one. Run it on an otherwise idle machine with two free cores: a
second thread that waits for its core makes a run slower, not faster.
"""
import json
import math
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
# (label, process, example, solver members, bundle rings or None for the example's).
CASES = [
    ("row17", "bundle-dynamics", "bundle-row17", {}, None),
    ("hex217", "hex-bundle-dynamics", "hex217", {}, None),
    ("hex217 check none", "hex-bundle-dynamics", "hex217", {"check": "none"}, None),
    ("hex61", "hex-bundle-dynamics", "hex217", {}, 4),
    ("hex61 check none", "hex-bundle-dynamics", "hex217", {"check": "none"}, 4),
    ("hex19 check none", "hex-bundle-dynamics", "hex217", {"check": "none"}, 2),
    ("cantilever", "cantilever-impact", "cantilever-impact", {}, None),
]


def inputs(example, solver, rings, threads, directory):
    document = json.loads((ROOT / "examples" / f"{example}.json").read_text())
    document["inputs"].setdefault("solver", {}).update(solver, threads=threads)
    if rings is not None:
        # As scripts/hex-scaling.sh: the wrapper resized to keep the 0.5 mm clearance.
        bundle = document["inputs"]["bundle"]
        bundle["rings"] = rings
        bundle["wrapper_flat_to_flat"] = 2 * (
            0.0005 + rings * bundle["pitch"] * math.sqrt(3) / 2 + 0.0097 / 2 + bundle["wire_diameter"]
        )
    path = pathlib.Path(directory) / f"{example}-{len(solver)}-{rings}-{threads}.json"
    path.write_text(json.dumps(document))
    return path


def run(binary, process, path):
    before, started = os.times(), time.monotonic()
    out = subprocess.run([binary, "run", process, str(path)], check=True, capture_output=True, text=True).stdout
    wall, after = time.monotonic() - started, os.times()
    cpu = (after.children_user - before.children_user) + (after.children_system - before.children_system)
    quality = json.loads(out).get("quality") or {}
    return wall, cpu, (quality.get("step_halving") or {}).get("compared_with")


def main():
    args = sys.argv[1:]
    rounds = 3
    if "--rounds" in args:
        at = args.index("--rounds")
        rounds = int(args[at + 1])
        del args[at : at + 2]
    binaries = args
    walls, cpus, checks = {}, {}, {}
    with tempfile.TemporaryDirectory() as directory:
        for _ in range(rounds):
            for label, process, example, solver, rings in CASES:
                for threads in (1, 2):
                    path = inputs(example, solver, rings, threads, directory)
                    for binary in binaries:
                        key = (label, binary, threads)
                        wall, cpu, check = run(binary, process, path)
                        walls.setdefault(key, []).append(wall)
                        cpus.setdefault(key, []).append(cpu)
                        checks[key] = check
    for label, *_ in CASES:
        for binary in binaries:
            wall = {t: statistics.median(walls[(label, binary, t)]) for t in (1, 2)}
            cpu = {t: statistics.median(cpus[(label, binary, t)]) for t in (1, 2)}
            print(
                f"{label} [{binary}] (check {checks[(label, binary, 1)]}): "
                f"1 thread {wall[1]:.3f} s wall {cpu[1]:.3f} s CPU, "
                f"2 threads {wall[2]:.3f} s wall {cpu[2]:.3f} s CPU, speed-up {wall[1] / wall[2]:.2f}"
            )


if __name__ == "__main__":
    main()
