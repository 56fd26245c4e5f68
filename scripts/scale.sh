#!/usr/bin/env bash
# Throughput of the scale-out deployment: one API process (`serve --workers 0`) and 1,
# then 2, worker processes (`worker --workers 1`) on one PostgreSQL database, each round
# computing the same sweep on a fresh database. Prints jobs/s per round.
#
#   scripts/scale.sh [RUNS] [SIMULATED_SECONDS]
#
# RUNS (default 60) cantilever-impact runs, each SIMULATED_SECONDS (default 2) of
# simulated time at a 10 µs step (~0.2 s of computing each on a 2-core VM).
# CHOCMODAL_BIN: the binary (default target/release/chocmodal, built if missing).
# WORKER_COUNTS: the rounds (default "1 2"). A throwaway PostgreSQL cluster is started
# from /usr/lib/postgresql/<version>/bin (run as `nobody` when root) and removed at exit.
set -euo pipefail
cd "$(dirname "$0")/.."

runs=${1:-60}
simulated=${2:-2}
worker_counts=${WORKER_COUNTS:-"1 2"}
bin=${CHOCMODAL_BIN:-target/release/chocmodal}
if [ ! -x "$bin" ]; then
    cargo build --release --bin chocmodal
fi
bin=$(realpath "$bin")
pg_bin=$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -n 1)
[ -x "$pg_bin/initdb" ] || { echo "no PostgreSQL server binaries: apt-get install postgresql" >&2; exit 1; }

work=$(mktemp -d /tmp/chocmodal-scale-XXXXXX)
as_pg=()
if [ "$(id -u)" = 0 ]; then
    chown nobody: "$work"
    as_pg=(runuser -u nobody --)
fi
pids=()
cleanup() {
    for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
    wait 2>/dev/null || true
    "${as_pg[@]}" "$pg_bin/pg_ctl" -D "$work/data" -m fast stop >/dev/null 2>&1 || true
    rm -rf "$work"
}
trap cleanup EXIT

free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'; }
pg_port=$(free_port)
"${as_pg[@]}" "$pg_bin/initdb" -D "$work/data" -U chocmodal --auth=trust --no-sync -E UTF8 --locale=C >/dev/null
"${as_pg[@]}" "$pg_bin/pg_ctl" -D "$work/data" -l "$work/postgres.log" -w \
    -o "-p $pg_port -k $work -h 127.0.0.1 -c max_connections=200" start >/dev/null
psql() { "$pg_bin/psql" -h 127.0.0.1 -p "$pg_port" -U chocmodal -v ON_ERROR_STOP=1 -qAt "$@"; }

# Waits until a process's JSON log has a line with this message.
wait_for_log() {
    local log=$1 message=$2
    for _ in $(seq 1 300); do
        grep -q "\"message\":\"$message\"" "$log" 2>/dev/null && return 0
        sleep 0.1
    done
    echo "no '$message' in $log:" >&2
    cat "$log" >&2
    exit 1
}

sweep=$(python3 - "$runs" "$simulated" <<'EOF'
import json, sys
runs, simulated = int(sys.argv[1]), float(sys.argv[2])
print(json.dumps({
    "process": "cantilever-impact",
    "inputs": {
        "beam": {"length": 1.0, "young_modulus": 2.1e11, "density": 7800.0,
                 "section": {"type": "tube", "outer_diameter": 0.010, "inner_diameter": 0.009}},
        "contact": {"rk": 1.0},
        "release": {"tip_displacement": 0.001},
        "solver": {"time_step": 1e-5, "duration": simulated},
        "output": {"interval": 1e-3},
    },
    "axes": [{"pointer": "/contact/rk", "logspace": [0.1, 100.0, runs]}],
}))
EOF
)

echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
echo "# $runs cantilever-impact runs of ${simulated} s simulated; load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
printf '%-8s %-10s %-8s\n' workers seconds jobs/s
for workers in $worker_counts; do
    db="scale_${workers}_$$"
    psql -d postgres -c "CREATE DATABASE $db"
    url="postgres://chocmodal@127.0.0.1:$pg_port/$db"
    port=$(free_port)
    CHOCMODAL_LOG_FORMAT=json "$bin" serve --workers 0 --bind "127.0.0.1:$port" --database "$url" \
        2>"$work/api-$workers.log" &
    pids+=($!)
    api_pid=$!
    wait_for_log "$work/api-$workers.log" "chocmodal is ready"
    round=()
    for w in $(seq 1 "$workers"); do
        CHOCMODAL_LOG_FORMAT=json "$bin" worker --workers 1 --database "$url" \
            2>"$work/worker-$workers-$w.log" &
        pids+=($!)
        round+=($!)
        wait_for_log "$work/worker-$workers-$w.log" "chocmodal worker is ready"
    done
    start=$(date +%s.%N)
    location=$(curl -fsS -o /dev/null -w '%header{location}' "http://127.0.0.1:$port/sweeps" \
        -H 'content-type: application/json' -d "$sweep")
    while :; do
        status=$(curl -fsS "http://127.0.0.1:$port$location" | python3 -c 'import json,sys; print(json.load(sys.stdin)["status"])')
        [ "$status" = accepted ] || [ "$status" = running ] || break
        sleep 0.1
    done
    end=$(date +%s.%N)
    [ "$status" = successful ] || { echo "sweep ended $status" >&2; exit 1; }
    failed=$(psql -d "$db" -c "SELECT COUNT(*) FROM jobs WHERE status <> 'successful'")
    [ "$failed" = 0 ] || { echo "$failed runs did not succeed" >&2; exit 1; }
    python3 -c "import sys; s=float(sys.argv[2])-float(sys.argv[1]); print(f'{int(sys.argv[3]):<8} {s:<10.2f} {int(sys.argv[4])/s:<8.2f}')" \
        "$start" "$end" "$workers" "$runs"
    kill -TERM "$api_pid" "${round[@]}"
    wait "$api_pid" "${round[@]}" 2>/dev/null || true
done
