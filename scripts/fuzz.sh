#!/usr/bin/env bash
# Fuzzes a running chocmodal against its committed OpenAPI document with schemathesis
# (PyPI): no response may be a 5xx, and every response must conform to the schema the
# document gives for its status. Starts a release server on a free port with a fresh
# data directory and an auth file (so the bearer token path is exercised too), and
# stops it at the end.
#
#   scripts/fuzz.sh                      # ~50 cases per operation
#   FUZZ_EXAMPLES=500 scripts/fuzz.sh    # a longer hunt
#   FUZZ_SEED=42 scripts/fuzz.sh         # reproduce a run
#
# schemathesis is installed in a virtualenv under target/fuzz-venv (FUZZ_VENV to change).
set -euo pipefail
cd "$(dirname "$0")/.."

venv="${FUZZ_VENV:-target/fuzz-venv}"
schemathesis_version="${SCHEMATHESIS_VERSION:-4.32.5}"
if [ ! -x "$venv/bin/schemathesis" ]; then
    echo "installing schemathesis $schemathesis_version into $venv" >&2
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet "schemathesis==$schemathesis_version"
fi

cargo build --release --quiet --bin chocmodal

data="$(mktemp -d)"
port="$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')"
token="fuzz-$(python3 -c 'import secrets; print(secrets.token_hex(16))')"
printf '# scripts/fuzz.sh\nfuzz %s\n' "$token" > "$data/tokens"

# Small ceilings: whatever valid job the fuzzer invents stays short.
target/release/chocmodal serve --bind "127.0.0.1:$port" --data-dir "$data" --workers 2 \
    --auth-file "$data/tokens" --max-work 2e8 --max-job-seconds 20 --max-queued-jobs 500 \
    --log-format json 2> "$data/server.log" &
server=$!
cleanup() {
    kill "$server" 2> /dev/null || true
    wait "$server" 2> /dev/null || true
    [ -n "${keep:-}" ] || rm -rf "$data"
}
trap cleanup EXIT

for _ in $(seq 1 100); do
    curl -fsS "http://127.0.0.1:$port/healthz" > /dev/null 2>&1 && break
    sleep 0.1
done

root="$PWD"
args=(
    run "$root/openapi/openapi.json"
    --url "http://127.0.0.1:$port"
    --header "Authorization: Bearer $token"
    --checks "${FUZZ_CHECKS:-not_a_server_error,response_schema_conformance}"
    --max-examples "${FUZZ_EXAMPLES:-50}"
    --generation-database none
    --report junit --report-dir "$root/target/fuzz-report"
    --no-color
)
if [ -n "${FUZZ_SEED:-}" ]; then
    args+=(--seed "$FUZZ_SEED")
fi
# schemathesis keeps a cache of its findings in its working directory: not in the repo.
mkdir -p target/fuzz-report
venv="$(cd "$venv" && pwd)"
status=0
(cd target/fuzz-report && "$venv/bin/schemathesis" "${args[@]}") || status=$?

# A request may also have gone wrong without a 5xx: the server logs every fault.
if grep -q '"level":"ERROR"' "$data/server.log"; then
    keep=1
    echo "errors in the server log ($data/server.log kept):" >&2
    grep '"level":"ERROR"' "$data/server.log" | head -20 >&2
    status=1
fi
exit "$status"
