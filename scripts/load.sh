#!/usr/bin/env bash
# Latency of the API while every worker computes: starts a release server on a free
# port (fresh data directory, one bearer token), saturates its workers with long
# `bundle-dynamics` jobs (examples/bundle-row17.json over 20 s of simulated time, about
# a minute each), then measures with wrk:
#   1. GET /jobs/{id} (a running job's status, what pollers do), and
#   2. POST /processes/cantilever-impact/execution (validation + enqueue of the public
#      case; each request queues a job that never gets a worker during the test),
# and prints p50/p90/p99 and throughput, checking the workers stayed busy throughout.
#
#   scripts/load.sh                       # 20 s per measurement, 4 connections
#   LOAD_SECONDS=60 LOAD_CONNECTIONS=16 scripts/load.sh
#
# Needs wrk (`apt-get install wrk`), or set LOAD_TOOL=oha with oha installed
# (`cargo install oha`).
set -euo pipefail
cd "$(dirname "$0")/.."

seconds="${LOAD_SECONDS:-20}"
connections="${LOAD_CONNECTIONS:-4}"
workers="${LOAD_WORKERS:-$(nproc)}"
tool="${LOAD_TOOL:-wrk}"
command -v "$tool" > /dev/null || {
    echo "$tool not found: apt-get install wrk, or cargo install oha and LOAD_TOOL=oha" >&2
    exit 2
}

cargo build --release --quiet --bin chocmodal

data="$(mktemp -d)"
port="$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')"
token="load-$(python3 -c 'import secrets; print(secrets.token_hex(16))')"
printf 'load %s\n' "$token" > "$data/tokens"
target/release/chocmodal serve --bind "127.0.0.1:$port" --data-dir "$data" --workers "$workers" \
    --auth-file "$data/tokens" --max-queued-jobs 1000000 --log-format json 2> "$data/server.log" &
server=$!
trap 'kill $server 2> /dev/null || true; wait $server 2> /dev/null || true; rm -rf "$data"' EXIT
base="http://127.0.0.1:$port"
for _ in $(seq 1 100); do
    curl -fsS "$base/healthz" > /dev/null 2>&1 && break
    sleep 0.1
done
auth="Authorization: Bearer $token"

# Long jobs: twice as many as workers, so the queue never runs dry.
long="$(python3 - <<'PY'
import json
body = json.load(open("examples/bundle-row17.json"))
body["inputs"]["solver"]["duration"] = 20.0
body["inputs"]["output"] = {"interval": 1e-3}
print(json.dumps(body))
PY
)"
job=""
for _ in $(seq 1 $((2 * workers))); do
    id="$(curl -fsS -H "$auth" -H 'content-type: application/json' -d "$long" \
        "$base/processes/bundle-dynamics/execution" | python3 -c 'import json, sys; print(json.load(sys.stdin)["jobID"])')"
    job="${job:-$id}"
done

running() {
    curl -fsS -H "$auth" "$base/jobs?status=running&limit=1000" |
        python3 -c 'import json, sys; print(len(json.load(sys.stdin)["jobs"]))'
}
for _ in $(seq 1 100); do
    [ "$(running)" -ge "$workers" ] && break
    sleep 0.1
done

small="$(python3 -c 'import json; print(json.dumps(json.load(open("examples/cantilever-impact.json"))))')"
printf '%s' "$small" > "$data/small.json"
cat > "$data/post.lua" <<LUA
wrk.method = "POST"
wrk.headers["Content-Type"] = "application/json"
wrk.headers["Authorization"] = "Bearer $token"
local file = io.open("$data/small.json", "r")
wrk.body = file:read("*a")
file:close()
LUA

measure() { # name, method, url
    local name="$1" method="$2" url="$3"
    local before after
    before="$(running)"
    if [ "$tool" = oha ]; then
        local extra=()
        [ "$method" = POST ] && extra=(-m POST -T application/json -D "$data/small.json")
        oha --no-tui -z "${seconds}s" -c "$connections" -H "$auth" "${extra[@]}" --output-format json "$url" \
            > "$data/$name.json"
        python3 - "$data/$name.json" "$name" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
p = r["latencyPercentiles"]; s = r["summary"]
codes = r.get("statusCodeDistribution", {})
print(f"{sys.argv[2]}: {s['requestsPerSec']:.0f} req/s, p50 {p['p50']*1e3:.2f} ms, "
      f"p90 {p['p90']*1e3:.2f} ms, p99 {p['p99']*1e3:.2f} ms, statuses {codes}")
PY
    else
        local script=()
        [ "$method" = POST ] && script=(-s "$data/post.lua")
        wrk -t 2 -c "$connections" -d "${seconds}s" --latency -H "$auth" "${script[@]}" "$url" \
            > "$data/$name.txt"
        python3 - "$data/$name.txt" "$name" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
def ms(label):
    m = re.search(rf"^\s*{label}%\s+([\d.]+)(us|ms|s)\s*$", text, re.M)
    value, unit = float(m.group(1)), m.group(2)
    return value * {"us": 1e-3, "ms": 1.0, "s": 1e3}[unit]
rate = float(re.search(r"Requests/sec:\s+([\d.]+)", text).group(1))
errors = re.search(r"Non-2xx or 3xx responses: (\d+)", text)
print(f"{sys.argv[2]}: {rate:.0f} req/s, p50 {ms(50):.2f} ms, p90 {ms(90):.2f} ms, "
      f"p99 {ms(99):.2f} ms, non-2xx {errors.group(1) if errors else 0}")
PY
    fi
    after="$(running)"
    echo "  running jobs before/after: $before/$after of $workers workers"
}

echo "$(date -u +%Y-%m-%dT%H:%MZ), $(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)), $workers workers busy with long jobs, $tool, $connections connections, ${seconds}s each"
measure status GET "$base/jobs/$job"
measure submit POST "$base/processes/cantilever-impact/execution"
queued="$(curl -fsS -H "$auth" "$base/jobs?status=accepted&limit=1000" | python3 -c 'import json, sys; print(len(json.load(sys.stdin)["jobs"]))')"
echo "  queued jobs at the end: $queued (first page, at most 1000)"
