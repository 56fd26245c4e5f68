#!/usr/bin/env bash
# Peak memory of the server while it serves 8 concurrent full-resolution JSON histories
# of a large run (issue 30): runs one long `cantilever-impact` job (a history of
# HISTORY_SAMPLES samples, default 500 000, the default `--max-history-points`, so the
# JSON is full resolution), restarts the server on its database with no workers (so the
# job's computation is not in the figure), then fires HISTORY_CLIENTS (default 8)
# concurrent `GET /jobs/{id}/results/tip_displacement?format=json` and prints the
# server's peak RSS (VmHWM of /proc/<pid>/status) before and after, the bytes served,
# and the status of every response (200, or 503 `server-busy` when the
# `--response-memory-mb` budget is spent).
#
#   scripts/history-memory.sh                       # release build
#   PROFILE=dev scripts/history-memory.sh           # quicker to build, same allocations
#   HISTORY_CLIENTS=16 RESPONSE_MEMORY_MB=256 scripts/history-memory.sh
#   CHOCMODAL_BIN=target/debug/chocmodal scripts/history-memory.sh   # a binary already built
#
# Linux only (reads /proc).
set -euo pipefail
cd "$(dirname "$0")/.."

profile="${PROFILE:-release}"
clients="${HISTORY_CLIENTS:-8}"
samples="${HISTORY_SAMPLES:-500000}"
budget="${RESPONSE_MEMORY_MB:-1024}"
target_dir="${CARGO_TARGET_DIR:-target}"
if [ -n "${CHOCMODAL_BIN:-}" ]; then
    binary="$CHOCMODAL_BIN"
else
    case "$profile" in
        dev) binary="$target_dir/debug/chocmodal" ;;
        *) binary="$target_dir/$profile/chocmodal" ;;
    esac
    cargo build --profile "$profile" --quiet --bin chocmodal
fi

data="$(mktemp -d)"
server=""
stop_server() {
    if [ -n "$server" ]; then
        kill "$server" 2> /dev/null || true
        wait "$server" 2> /dev/null || true
        server=""
    fi
}
trap 'stop_server; rm -rf "$data"' EXIT

start_server() { # workers
    local port
    port="$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')"
    "$binary" serve --bind "127.0.0.1:$port" --data-dir "$data" --workers "$1" \
        --response-memory-mb "$budget" --log-format json 2>> "$data/server.log" &
    server=$!
    base="http://127.0.0.1:$port"
    for _ in $(seq 1 200); do
        curl -fsS "$base/healthz" > /dev/null 2>&1 && return 0
        sleep 0.1
    done
    echo "the server did not start; see $data/server.log" >&2
    cat "$data/server.log" >&2
    exit 1
}

peak_rss_kib() {
    awk '/^VmHWM:/ {print $2}' "/proc/$server/status"
}

start_server 1
# One sample per step: `samples` steps of 1e-5 s.
body="$(python3 - "$samples" <<'PY'
import json, sys
samples = int(sys.argv[1])
body = json.load(open("examples/cantilever-impact.json"))
body["inputs"]["solver"]["time_step"] = 1e-5
body["inputs"]["solver"]["duration"] = (samples - 1) * 1e-5
body["inputs"]["output"] = {"interval": 1e-5}
print(json.dumps(body))
PY
)"
job="$(curl -fsS -H 'content-type: application/json' -d "$body" "$base/processes/cantilever-impact/execution" \
    | python3 -c 'import json, sys; print(json.load(sys.stdin)["jobID"])')"
echo "job $job: computing a history of $samples samples"
while :; do
    status="$(curl -fsS "$base/jobs/$job" | python3 -c 'import json, sys; print(json.load(sys.stdin)["status"])')"
    case "$status" in
        successful) break ;;
        failed | dismissed) echo "the job $status" >&2; curl -sS "$base/jobs/$job" >&2; exit 1 ;;
    esac
    sleep 1
done
stop_server

start_server 0
path="/jobs/$job/results/tip_displacement?format=json"
# One request alone first: the size of the document, and the server warmed up.
single="$(curl -fsS -o /dev/null -w '%{size_download}' "$base$path")"
baseline="$(peak_rss_kib)"
echo "one full-resolution JSON history: $single bytes; server peak RSS so far: $((baseline / 1024)) MiB"

pids=()
for k in $(seq 1 "$clients"); do
    curl -sS -o /dev/null -w '%{http_code} %{size_download}\n' "$base$path" > "$data/client-$k" &
    pids+=("$!")
done
for pid in "${pids[@]}"; do wait "$pid"; done
peak="$(peak_rss_kib)"
served=0
ok=0
busy=0
for k in $(seq 1 "$clients"); do
    read -r code size < "$data/client-$k"
    served=$((served + size))
    case "$code" in
        200) ok=$((ok + 1)) ;;
        503) busy=$((busy + 1)) ;;
        *) echo "client $k: HTTP $code" >&2; exit 1 ;;
    esac
done
echo "$clients concurrent GETs: $ok answered 200, $busy answered 503 (budget ${budget} MiB); $((served / 1048576)) MiB served"
echo "server peak RSS (VmHWM): $((peak / 1024)) MiB (before the concurrent GETs: $((baseline / 1024)) MiB)"
