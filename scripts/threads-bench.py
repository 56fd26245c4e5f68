#!/usr/bin/env python3
"""Wall time of the shipped examples on one and on two threads, interleaved, for one
binary or more (the previous one beside the new one).

Usage: scripts/threads-bench.py BINARY [BINARY ...] [--rounds N]

Runs `chocmodal run` on row17 (examples/bundle-row17.json), hex217 (examples/hex217.json)
and the public cantilever (examples/cantilever-impact.json), each as shipped (the step
check at its default) and hex217 also with `check: "none"` (its steps shared, nothing to
run beside them), with `solver.threads` 1 and 2, alternating binaries and counts within
each round. Prints the median wall and CPU time (user + system) of each and the speed-up
of two threads over one. Run it on an otherwise idle machine with two free cores: a
second thread that waits for its core makes a run slower, not faster.
"""
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
CASES = [
    ("row17", "bundle-dynamics", "bundle-row17", {}),
    ("hex217", "hex-bundle-dynamics", "hex217", {}),
    ("hex217 check none", "hex-bundle-dynamics", "hex217", {"check": "none"}),
    ("cantilever", "cantilever-impact", "cantilever-impact", {}),
]


def inputs(example, solver, threads, directory):
    document = json.loads((ROOT / "examples" / f"{example}.json").read_text())
    document["inputs"].setdefault("solver", {}).update(solver, threads=threads)
    path = pathlib.Path(directory) / f"{example}-{len(solver)}-{threads}.json"
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
            for label, process, example, solver in CASES:
                for threads in (1, 2):
                    path = inputs(example, solver, threads, directory)
                    for binary in binaries:
                        key = (label, binary, threads)
                        wall, cpu, check = run(binary, process, path)
                        walls.setdefault(key, []).append(wall)
                        cpus.setdefault(key, []).append(cpu)
                        checks[key] = check
    for label, _, _, _ in CASES:
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
