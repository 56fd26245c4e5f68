#!/usr/bin/env python3
"""examples/hex7-loads.json over 0.03 s (check off, auto steps) with a given scheme, static
correction, rings and modes: peak contact force, steps, wall time, energy residual, verdict.
Usage (from the repository root, after `cargo build --release`):
    python3 scripts/exact-modal-hex.py SCHEME,CORRECTION,RINGS[,MODES] ...
with no argument: the docs/static-correction.md table."""
import json,subprocess,time,sys
d=json.load(open('examples/hex7-loads.json'))
def run(scheme, corr, rings, modes=10, duration=0.03, check='none'):
    e=json.loads(json.dumps(d)); e['inputs']['pin']['static_correction']=corr; e['inputs']['pin']['modes']=modes
    e['inputs']['bundle']['rings']=rings
    e['inputs']['bundle']['wrapper_flat_to_flat']=0.0305 + 2*rings*0.0107 - 2*0.0107
    e['inputs']['solver'].update({'scheme':scheme,'duration':duration,'check':check,'time_step':'auto'})
    open('/tmp/hx.json','w').write(json.dumps(e))
    t=time.time(); p=subprocess.run(['./target/release/chocmodal','run','hex-bundle-dynamics','/tmp/hx.json'],capture_output=True,text=True); w=time.time()-t
    if p.returncode: print(scheme,corr,rings,'FAILED',p.stderr[-300:]); return
    r=json.loads(p.stdout); peak=max(c['max_force'] for c in r['contacts'])
    print(f"rings {rings} {scheme:18s} {corr:8s} modes {modes} peak {peak:9.4f} steps {r['steps']:7d} wall {w:6.2f} s energy {r['energy'].get('relative_residual'):.2e} verdict {r['quality']['verdict']}", flush=True)
for a in sys.argv[1:] or ['central_difference,none,1', 'exact_modal,none,1', 'central_difference,contacts,1', 'exact_modal,contacts,1']:
    p=a.split(','); run(p[0],p[1],int(p[2]),int(p[3]) if len(p)>3 else 10)
