#!/usr/bin/env bash
# The workstation server under HTTP load: wrk against a scan's measurements (JSON)
# and its mesh (GLB), first with the rig idle, then while a long scan runs.
#   [BODYSCAN_BIN=PATH] [DURATION=15] [THREADS=2] [CONNECTIONS=50] [FIRST_EVERY=6] bench/server_load.sh [--json OUT]
# Builds nothing. Starts its own server on a free port with a throw-away archive and
# an empty web root, makes one scan (every=6, ~45 s with calibration on 2 cores:
# the sparsest that closes the surface and gives the automatic measurements) to
# have a mesh and measurements, measures, then starts a scan with every=1
# (~2-3 min) and measures again while it runs, cancels it and stops the server.
# (every=12 leaves the surface in pieces and the measurements list empty.)
# Prints a markdown table; with --json OUT.json also writes its rows with the run's
# provenance (bench/tables.py --wrap). Needs curl, wrk (Debian package wrk) and python3.
# KEEP_LOGS=1 keeps the temp dir (server log, wrk outputs) and says where.
set -euo pipefail

here="$(cd "$(dirname "$0")/.." && pwd)"
json_out=""
if [[ "${1:-}" == --json && -n "${2:-}" ]]; then json_out="$(realpath "$2")"; fi
duration="${DURATION:-15}"
threads="${THREADS:-2}"
connections="${CONNECTIONS:-50}"
password="bench-$$-$RANDOM$RANDOM"

if [[ -n "${BODYSCAN_BIN:-}" ]]; then
  bin="$(realpath "$BODYSCAN_BIN")"
elif "$here/build/app/bodyscan" serve --help >/dev/null 2>&1; then
  bin="$here/build/app/bodyscan"
else
  bin="$here/build-test/app/bodyscan"
fi
"$bin" serve --help >/dev/null 2>&1 || { echo "server_load: $bin has no 'serve' command" >&2; exit 1; }
for tool in curl wrk python3; do
  command -v "$tool" >/dev/null || { echo "server_load: needs $tool" >&2; exit 1; }
done

tmp="$(mktemp -d "${TMPDIR:-/tmp}/bodyscan-load.XXXXXX")"
server_pid=""
cleanup() {
  local rc=$?
  if [[ -n "$server_pid" ]] && kill -0 "$server_pid" 2>/dev/null; then
    kill -TERM "$server_pid" 2>/dev/null || true
    for _ in $(seq 100); do kill -0 "$server_pid" 2>/dev/null || break; sleep 0.1; done
    if kill -0 "$server_pid" 2>/dev/null; then kill -KILL "$server_pid" 2>/dev/null || true; fi
    wait "$server_pid" 2>/dev/null || true
  fi
  if [[ "${KEEP_LOGS:-0}" == 1 ]]; then
    echo "server_load: logs kept in $tmp" >&2
  else
    rm -rf "$tmp"
  fi
  exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

log() { echo "server_load: $*" >&2; }
# A JSON field by a Python expression on `j`, from stdin.
jget() { python3 -c 'import json,sys; j=json.load(sys.stdin); print(eval(sys.argv[1]))' "$1"; }

# --- the server -------------------------------------------------------------------
mkdir -p "$tmp/data" "$tmp/web"
BODYSCAN_ADMIN_PASSWORD="$password" "$bin" serve --data "$tmp/data" --port 0 --web "$tmp/web" \
  >"$tmp/server.log" 2>&1 &
server_pid=$!
port=""
for _ in $(seq 300); do
  port="$(sed -n 's|^open https\?://[^:]*:\([0-9]*\)/.*|\1|p' "$tmp/server.log" | head -n1)"
  [[ -n "$port" ]] && break
  kill -0 "$server_pid" 2>/dev/null || { cat "$tmp/server.log" >&2; log "the server exited"; exit 1; }
  sleep 0.1
done
[[ -n "$port" ]] || { cat "$tmp/server.log" >&2; log "the server did not say its port"; exit 1; }
base="http://127.0.0.1:$port"
log "server pid $server_pid on $base ($bin)"

# --- logging in ------------------------------------------------------------------
code="$(curl -sS -o "$tmp/login.json" -D "$tmp/login.headers" -w '%{http_code}' \
  -H 'Content-Type: application/json' \
  --data "{\"username\":\"admin\",\"password\":\"$password\"}" "$base/api/login")"
[[ "$code" == 200 ]] || { log "login: HTTP $code: $(cat "$tmp/login.json")"; exit 1; }
session="$(sed -n 's/^[Ss]et-[Cc]ookie: *bodyscan_session=\([^;]*\).*/\1/p' "$tmp/login.headers" | tr -d '\r' | head -n1)"
csrf="$(jget 'j["csrf_token"]' <"$tmp/login.json")"
[[ -n "$session" && -n "$csrf" ]] || { log "login gave no session cookie or CSRF token"; exit 1; }
cookie="Cookie: bodyscan_session=$session"

# api METHOD PATH [BODY] -> the body on stdout; the status in $tmp/status.
api() {
  local args=(-sS -o "$tmp/body" -w '%{http_code}' -X "$1" -H "$cookie")
  if [[ "$1" != GET ]]; then
    local body="${3:-}"
    [[ -n "$body" ]] || body='{}'
    args+=(-H "X-CSRF-Token: $csrf" -H 'Content-Type: application/json' --data "$body")
  fi
  curl "${args[@]}" "$base$2" >"$tmp/status"
  cat "$tmp/body"
}
status() { cat "$tmp/status"; }

# job_field ID EXPR: a field of GET /api/jobs/ID.
job_json() { api GET "/api/jobs/$1"; }
job_line() {  # "state stage fraction"
  job_json "$1" | jget '"%s %s %.3f" % (j["job"]["state"], j["job"].get("stage"), j["job"].get("fraction") or 0)'
}

start_scan() {  # EVERY; sets job_id and scan_id
  local out
  out="$(api POST /api/scans "{\"customer\":{\"name\":\"Bench\"},\"consent\":true,\"every\":$1}")"
  [[ "$(status)" == 202 ]] || { log "POST /api/scans (every=$1): HTTP $(status): $out"; exit 1; }
  scan_id="$(jget 'j["job"]["scan_id"]' <<<"$out")"
  job_id="$(jget 'j["job"]["id"]' <<<"$out")"
}

# --- the scan to read --------------------------------------------------------------
t0=$SECONDS
start_scan "${FIRST_EVERY:-6}"
job="$job_id"
log "scan $scan_id (job $job, every=${FIRST_EVERY:-6}) started; waiting for it"
while :; do
  line="$(job_line "$job")"
  case "${line%% *}" in
    complete) break ;;
    failed|cancelled) log "the first scan ended $line: $(cat "$tmp/body")"; exit 1 ;;
  esac
  (( SECONDS - t0 < 600 )) || { log "the first scan did not finish in 600 s ($line)"; exit 1; }
  sleep 1
done
log "scan $scan_id complete in $((SECONDS - t0)) s"
read_scan="$scan_id"
json_url="$base/api/scans/$read_scan/measurements"
glb_url="$base/api/scans/$read_scan/mesh.glb"

size_of() {  # URL -> "bytes status content-type"
  curl -sS -o /dev/null -H "$cookie" -w '%{size_download} %{http_code} %{content_type}' "$1"
}
alone_ms() {  # URL -> the median of 5 single requests' times, ms
  local _
  for _ in 1 2 3 4 5; do curl -sS -o /dev/null -H "$cookie" -w '%{time_total}\n' "$1"; done |
    sort -n | sed -n 3p | awk '{printf "%.1f", $1 * 1000}'
}
json_size="$(size_of "$json_url")"
glb_size="$(size_of "$glb_url")"
for s in "$json_size" "$glb_size"; do
  read -r _ c _ <<<"$s"
  [[ "$c" == 200 ]] || { log "a GET before the load gave HTTP $c ($s)"; exit 1; }
done
# How much the JSON case carries: the automatic measurements can fail on a sparse
# scan (the version's note says why), leaving an empty list.
n_measurements="$(api GET "/api/scans/$read_scan/measurements" | jget 'len(j["measurements"])')"
scan_note="$(api GET "/api/scans/$read_scan" | jget '"; ".join(v.get("note") or "" for v in j.get("versions", []) if v.get("note")) or "none"')"
log "scan $read_scan: $n_measurements measurements; version note: $scan_note"
json_alone="$(alone_ms "$json_url")"
glb_alone="$(alone_ms "$glb_url")"

# --- the load ------------------------------------------------------------------------
rows=()
notes=()
run_wrk() {  # NAME URL [HEADER]
  local out="$tmp/wrk-${#rows[@]}.txt"
  local extra=()
  if [[ -n "${3:-}" ]]; then extra=(-H "$3"); fi
  log "wrk: $1 (${duration}s)"
  wrk -t"$threads" -c"$connections" -d"${duration}s" --latency -H "$cookie" "${extra[@]}" "$2" >"$out" 2>&1 ||
    { cat "$out" >&2; log "wrk failed"; exit 1; }
  if [[ "${VERBOSE:-0}" == 1 ]]; then cat "$out" >&2; fi
  rows+=("$(python3 "$tmp/parse_wrk.py" "$1" "$out" "$tmp/records.jsonl")")
  settle "$1"
}

# Requests wrk gave up on (its timeout is 2 s) can still be queued in the server when
# wrk stops: wait until a cheap request is quick again, so that they do not spill
# into the next case, and say how long that took.
settle() {
  local t0=$SECONDS t
  while :; do
    t="$(curl -sS -o /dev/null -H "$cookie" -w '%{time_total}' "$base/api/jobs/$job")"
    awk -v t="$t" 'BEGIN { exit !(t < 0.1) }' && break
    (( SECONDS - t0 < 60 )) || { notes+=("- after $1: the server was still slow 60 s later (a request took ${t} s)"); return; }
    sleep 0.5
  done
  if (( SECONDS - t0 >= 1 )); then notes+=("- after $1: the server took ~$((SECONDS - t0)) s to answer a cheap request quickly again"); fi
}

cat >"$tmp/parse_wrk.py" <<'EOF'
import json, re, sys
name, path, records = sys.argv[1], sys.argv[2], sys.argv[3]
text = open(path).read()
def ms(v):
    m = re.fullmatch(r"([\d.]+)(us|ms|s|m|h)", v)
    if not m: return float("nan")
    return float(m[1]) * {"us": 1e-3, "ms": 1, "s": 1e3, "m": 6e4, "h": 3.6e6}[m[2]]
def mb(v):
    m = re.fullmatch(r"([\d.]+)(B|KB|MB|GB|TB)", v)
    if not m: return float("nan")
    return float(m[1]) * {"B": 1 / 2**20, "KB": 1 / 2**10, "MB": 1, "GB": 2**10, "TB": 2**20}[m[2]]
def find(pattern, default=None):
    m = re.search(pattern, text, re.M)
    return m[1] if m else default
rps = float(find(r"^Requests/sec:\s*([\d.]+)", "nan"))
p50 = ms(find(r"^\s*50%\s+(\S+)", ""))
p99 = ms(find(r"^\s*99%\s+(\S+)", ""))
xfer = mb(find(r"^Transfer/sec:\s*(\S+)", ""))
total = find(r"^\s*(\d+) requests in", "?")
non2xx = int(find(r"^\s*Non-2xx or 3xx responses:\s*(\d+)", "0"))
sock = re.search(r"Socket errors: connect (\d+), read (\d+), write (\d+), timeout (\d+)", text)
parts = []
if non2xx: parts.append(f"non-2xx {non2xx}")
if sock:
    for label, v in zip(("connect", "read", "write", "timeout"), sock.groups()):
        if int(v): parts.append(f"{label} {v}")
errors = non2xx + (sum(map(int, sock.groups())) if sock else 0)
detail = f" ({', '.join(parts)})" if parts else ""
print(f"| {name} | {rps:.0f} | {p50:.1f} | {p99:.1f} | {xfer:.1f} | {errors} of {total}{detail} |")
with open(records, "a") as f:
    f.write(json.dumps({"case": name, "requests_per_s": rps, "p50_ms": p50, "p99_ms": p99, "transfer_mb_s": xfer,
                        "errors": errors, "error_detail": ", ".join(parts), "requests": int(total)}) + "\n")
EOF

run_wrk "measurements JSON, idle" "$json_url"
run_wrk "measurements JSON gzip (as browsers ask), idle" "$json_url" "Accept-Encoding: gzip"
run_wrk "mesh.glb, idle" "$glb_url"

t0=$SECONDS
start_scan 1
long_job="$job_id"
log "scan $scan_id (job $long_job, every=1) started"
sleep 2  # past the job's first moments
out="$(api POST /api/scans '{"customer":{"name":"Bench (should be refused)"},"consent":true,"every":12}')"
busy_check="a second POST /api/scans while it runs: HTTP $(status)"
[[ "$(status)" == 409 ]] || busy_check+=" (expected 409): $out"
notes+=("- $busy_check")
log "$busy_check"
during() {  # NAME URL [HEADER]
  local before after
  before="$(job_line "$long_job")"
  run_wrk "$1" "$2" "${3:-}"
  after="$(job_line "$long_job")"
  local verdict="running throughout"
  [[ "${before%% *}" == running && "${after%% *}" == running ]] || verdict="NOT running throughout"
  notes+=("- $1: scan $verdict (before: $before; after: $after)")
  log "$1: scan $verdict (before: $before; after: $after)"
}
during "measurements JSON, during a scan" "$json_url"
during "measurements JSON gzip, during a scan" "$json_url" "Accept-Encoding: gzip"
during "mesh.glb, during a scan" "$glb_url"

final="$(job_line "$long_job")"
if [[ "${final%% *}" == running ]]; then
  out="$(api POST "/api/jobs/$long_job/cancel")"
  [[ "$(status)" == 202 ]] || log "cancel: HTTP $(status): $out"
  for _ in $(seq 120); do
    final="$(job_line "$long_job")"
    [[ "${final%% *}" == running ]] || break
    sleep 0.5
  done
  log "job $long_job after cancelling: $final"
fi
notes+=("- the every=1 scan, $((SECONDS - t0)) s after starting: $final")

kill -TERM "$server_pid"
stopped=""
for _ in $(seq 300); do kill -0 "$server_pid" 2>/dev/null || { stopped=1; break; }; sleep 0.1; done
server_rc=0
if [[ -n "$stopped" ]]; then wait "$server_pid" || server_rc=$?; else server_rc="still running after 30 s"; fi
server_pid=""
grep -q 'stopped cleanly' "$tmp/server.log" || log "the server did not say it stopped cleanly (exit $server_rc)"

# --- the report ----------------------------------------------------------------------
cpu="$(sed -n 's/^model name[[:space:]]*: *//p' /proc/cpuinfo | head -n1)"
[[ -n "$cpu" ]] || cpu="$(lscpu 2>/dev/null | sed -n 's/^Model name: *//p' | head -n1)"
build_type="$(sed -n 's/^CMAKE_BUILD_TYPE:STRING=//p' "$(dirname "$bin")/../CMakeCache.txt" 2>/dev/null || true)"
build_type="${build_type:-build type unknown}"
read -r json_bytes _ json_type <<<"$json_size"
read -r glb_bytes _ glb_type <<<"$glb_size"
cat <<EOF

## Workstation server under load

machine: $(nproc) CPUs, ${cpu:-unknown CPU}; load average at the end $(cut -d' ' -f1-3 /proc/loadavg)
server: $bin ($build_type) serve (default --workers), archive in a temp dir
command: wrk -t$threads -c$connections -d${duration}s --latency -H "Cookie: bodyscan_session=..." URL
responses: GET /api/scans/ID/measurements $json_bytes bytes ($json_type, $n_measurements measurements), $json_alone ms alone; GET /api/scans/ID/mesh.glb $glb_bytes bytes ($glb_type), $glb_alone ms alone (median of 5 single requests, idle)
scan read: every=${FIRST_EVERY:-6}, version note: $scan_note

| case | requests/s | p50 ms | p99 ms | transfer MB/s | errors (non-2xx or socket) |
|---|---:|---:|---:|---:|---|
EOF
printf '%s\n' "${rows[@]}"
echo
printf '%s\n' "${notes[@]}"
echo "- server exit status: $server_rc"
if [[ -n "$json_out" ]]; then
  python3 - "$tmp/records.jsonl" "$json_bytes" "$glb_bytes" "$n_measurements" "$duration" "$threads" "$connections" \
    <<'EOF' | "$here/bench/tables.py" --wrap "$json_out" "bench/server_load.sh --json OUT.json"
import json, sys
path, json_bytes, glb_bytes, measurements, duration, threads, connections = sys.argv[1:]
rows = [json.loads(line) for line in open(path)]
for r in rows:
    r.update(json_bytes=int(json_bytes), glb_bytes=int(glb_bytes), measurements=int(measurements),
             seconds=int(duration), threads=int(threads), connections=int(connections))
print(json.dumps(rows))
EOF
fi
