#!/usr/bin/env python3
"""Convergence study of a process input in time step, modes and elements together.

Runs `chocmodal run <process> <input>` (release binary) once per setting and prints the
peak contact force, the step, the verdict and the quality's estimates (modal basis,
mesh, step halving), so that a default run can be compared with refined ones:

    cargo build --release
    scripts/basis-study.py examples/bundle-row12-shock.json \
      '[{}, {"modes": 40, "elements": 80}, {"modes": 80, "elements": 160}, {"modes": 160, "elements": 160}]'

Each setting is an object whose keys `modes`, `elements`, `static_correction` go to the
pin (or beam) and `time_step`, `check`, `tolerance`, `scheme` to the solver. A third argument names
the process (default `bundle-dynamics`).
"""
import copy
import json
import subprocess
import sys
import time
from pathlib import Path

BINARY = Path(__file__).resolve().parent.parent / "target" / "release" / "chocmodal"


def main():
    base = json.loads(Path(sys.argv[1]).read_text())
    settings = json.loads(sys.argv[2])
    process = sys.argv[3] if len(sys.argv) > 3 else "bundle-dynamics"
    for setting in settings:
        document = copy.deepcopy(base)
        inputs = document["inputs"]
        pin = inputs.get("pin") or inputs["beam"]
        for key in ("modes", "elements", "static_correction"):
            if key in setting:
                pin[key] = setting[key]
        for key in ("time_step", "check", "tolerance", "scheme"):
            if key in setting:
                inputs.setdefault("solver", {})[key] = setting[key]
        path = Path("/tmp/basis-study-input.json")
        path.write_text(json.dumps(document))
        started = time.time()
        run = subprocess.run([str(BINARY), "run", process, str(path)], capture_output=True, text=True)
        if run.returncode != 0:
            print(json.dumps(setting), "failed:", run.stderr.strip()[-300:])
            continue
        out = json.loads(run.stdout)
        quality = out["quality"]
        peak = out.get("max_contact_force") or {}
        halving = quality.get("step_halving")
        print(
            json.dumps(setting),
            f"peak {peak.get('force', float('nan')):.6g} N",
            f"dt {out.get('time_step', float('nan')):.3g} s",
            f"steps {out.get('steps')}",
            f"verdict {quality['verdict']}",
            f"basis {quality['modal_truncation']['estimated_peak_force_error']:.3g}",
            f"mesh {quality['mesh']['estimated_peak_force_error']:.3g}",
            "step " + (f"{halving['estimated_peak_force_error']:.3g}" if halving else "-"),
            f"{time.time() - started:.1f} s",
            flush=True,
        )


if __name__ == "__main__":
    main()
