#!/usr/bin/env python3
"""examples/hex217.json's pins, wires, contacts and shock on a bundle of RINGS rings (the
wrapper the example's clearance away), `check: none`, `auto` steps, over DURATION s, under
a scheme and a static correction: peak contact force, steps, wall time, energy residual.
Usage (repository root, after `cargo build --release`):
    python3 scripts/exact-modal-hex217.py [--binary PATH]... [--rounds N] SCHEME,CORRECTION,RINGS,DURATION ...
Several binaries are run interleaved, case by case, round by round; the median wall
time of the rounds is printed."""
import json, statistics, subprocess, sys, tempfile, time

args = sys.argv[1:]
binaries, rounds, cases = [], 1, []
while args:
    a = args.pop(0)
    if a == '--binary':
        binaries.append(args.pop(0))
    elif a == '--rounds':
        rounds = int(args.pop(0))
    else:
        cases.append(a)
binaries = binaries or ['target/release/chocmodal']
example = json.load(open('examples/hex217.json'))
clearance = example['inputs']['bundle']['wrapper_flat_to_flat'] - (
    3 ** 0.5 * 8 * 0.0107 + 0.0097 + 2 * 0.001)


def body(scheme, correction, rings, duration):
    e = json.loads(json.dumps(example))
    i = e['inputs']
    i['pin']['static_correction'] = correction
    i['bundle']['rings'] = rings
    i['bundle']['wrapper_flat_to_flat'] = 3 ** 0.5 * rings * 0.0107 + 0.0097 + 2 * 0.001 + clearance
    i['solver'].update({'scheme': scheme, 'duration': duration, 'check': 'none', 'time_step': 'auto'})
    f = tempfile.NamedTemporaryFile('w', suffix='.json', delete=False)
    json.dump(e, f)
    f.close()
    return f.name


files = {c: body(*(lambda p: (p[0], p[1], int(p[2]), float(p[3])))(c.split(','))) for c in cases}
walls, results = {}, {}
for _ in range(rounds):
    for case, path in files.items():
        for binary in binaries:
            start = time.time()
            p = subprocess.run([binary, 'run', 'hex-bundle-dynamics', path], capture_output=True, text=True)
            walls.setdefault((case, binary), []).append(time.time() - start)
            results[(case, binary)] = p
for case in cases:
    for binary in binaries:
        p = results[(case, binary)]
        wall = statistics.median(walls[(case, binary)])
        if p.returncode:
            print(f'{case:36s} {binary}: FAILED {p.stderr.strip()[-200:]}')
            continue
        r = json.loads(p.stdout)
        peak = max(c['max_force'] for c in r['contacts'])
        print(f"{case:36s} {binary}: peak {peak:9.4f} N  steps {r['steps']:7d}  wall {wall:7.2f} s  "
              f"energy {r['energy']['relative_residual']:.2e}", flush=True)
