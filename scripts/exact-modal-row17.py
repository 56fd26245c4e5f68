#!/usr/bin/env python3
"""The static correction's cost on row17 (issue 29 item 4): examples/bundle-row17.json as
shipped (central difference, no correction, 1 us), with the correction under central
difference, and with the correction under exact_modal at its auto step; check on and off.
Whole process, median of ROUNDS interleaved rounds. Usage (repository root, after
`cargo build --release`): python3 scripts/exact-modal-row17.py [ROUNDS] [BINARY]"""
import json, statistics, subprocess, sys, tempfile, time

rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 3
binary = sys.argv[2] if len(sys.argv) > 2 else 'target/release/chocmodal'
base = json.load(open('examples/bundle-row17.json'))
cases = {
    'as shipped': ('central_difference', 'none', 1e-6),
    'correction, central difference': ('central_difference', 'contacts', 1e-6),
    'correction, exact_modal': ('exact_modal', 'contacts', 'auto'),
}
files = {}
for name, (scheme, correction, step) in cases.items():
    for check in ['auto', 'none']:
        body = json.loads(json.dumps(base))
        body['inputs']['pin']['static_correction'] = correction
        body['inputs']['solver'].update({'scheme': scheme, 'time_step': step, 'check': check})
        f = tempfile.NamedTemporaryFile('w', suffix='.json', delete=False)
        json.dump(body, f)
        f.close()
        files[(name, check)] = f.name
times, peaks = {}, {}
for _ in range(rounds):
    for key, path in files.items():
        start = time.time()
        out = subprocess.run([binary, 'run', 'bundle-dynamics', path], capture_output=True, text=True, check=True)
        times.setdefault(key, []).append(time.time() - start)
        result = json.loads(out.stdout)
        peaks[key] = (max(c['max_force'] for c in result['contacts']), result['steps'])
for check in ['auto', 'none']:
    shipped = statistics.median(times[('as shipped', check)])
    for name in cases:
        t = statistics.median(times[(name, check)])
        peak, steps = peaks[(name, check)]
        print(f'check {check:4s} {name:32s} peak {peak:8.3f} N  steps {steps:7d}  {t:.3f} s  {t / shipped:.2f}x')
