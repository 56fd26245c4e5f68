#!/usr/bin/env python3
"""The issue-29 row12 shock (examples/bundle-row12-shock.json) on a given basis and scheme, check off:
peak contact force, steps, wall time. Usage: python3 scripts/exact-modal-row12.py SCHEME,MODES,ELEMENTS,CORRECTION[,CHECK] ...
(run from the repository root after `cargo build --release`)."""
import json, subprocess, sys, time
base = json.load(open('examples/bundle-row12-shock.json'))
def run(scheme, modes, elements, corr, check='none'):
    d = json.loads(json.dumps(base))
    d['inputs']['pin'].update({'modes': modes, 'elements': elements, 'static_correction': corr})
    d['inputs']['solver'].update({'scheme': scheme, 'check': check})
    open('/tmp/req.json','w').write(json.dumps(d))
    t=time.time()
    p = subprocess.run(['./target/release/chocmodal','run','bundle-dynamics','/tmp/req.json'],capture_output=True,text=True)
    dt=time.time()-t
    if p.returncode: print(scheme,modes,elements,corr,'FAILED',p.stderr[-500:]); return
    r = json.loads(p.stdout)
    res = r.get('results', r)
    peak = max(c['max_force'] for c in res['contacts'])
    print(f"{scheme:20s} modes {modes:3d} el {elements:3d} {corr:8s} check {check:5s} peak {peak:9.3f} N steps {res['steps']:8d} dt {res['time_step']:.3e} wall {dt:6.2f} s verdict {res['quality']['verdict']}", flush=True)
for args in [a.split(',') for a in sys.argv[1:]]:
    run(args[0], int(args[1]), int(args[2]), args[3], *(args[4:]))
