#!/bin/sh
# Steps per second and cost per pin per step of `hex-bundle-dynamics` from 7 to 271 pins:
# examples/hex217.json with `rings` changed (the wrapper resized to keep the 0.5 mm wall
# clearance), 0.05 s simulated, no accuracy check. Usage: scripts/hex-scaling.sh
# (after `cargo build --release`).
set -e
bin=${BIN:-target/release/chocmodal}
printf '%6s %6s %9s %8s %10s %14s\n' rings pins contacts steps steps/s 'µs/pin/step'
for n in 1 2 3 4 5 6 7 8 9; do
  python3 - "$n" > /tmp/hex-scaling.json <<'PY'
import json, math, sys
n = int(sys.argv[1])
d = json.load(open('examples/hex217.json'))
b = d['inputs']['bundle']
b['rings'] = n
b['wrapper_flat_to_flat'] = 2 * (0.0005 + n * b['pitch'] * math.sqrt(3) / 2 + 0.0097 / 2 + b['wire_diameter'])
d['inputs']['solver'] = {'duration': 0.05, 'check': 'none'}
json.dump(d, sys.stdout)
PY
  start=$(date +%s.%N)
  "$bin" run hex-bundle-dynamics /tmp/hex-scaling.json > /tmp/hex-scaling-out.json
  end=$(date +%s.%N)
  python3 - "$n" "$start" "$end" <<'PY'
import json, sys
n, start, end = int(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
d = json.load(open('/tmp/hex-scaling-out.json'))
pins, steps, seconds = d['geometry']['pins'], d['steps'], end - start
print(f"{n:6d} {pins:6d} {d['geometry']['contacts']:9d} {steps:8d} {steps / seconds:10.0f} {1e6 * seconds / steps / pins:14.3f}")
PY
done
