#!/usr/bin/env bash
# Brings up deploy/compose.yaml with podman-compose and checks it from the host, through
# the router's published port, with the host's roam binary:
#   a. `roam plan` gets a plan (a path that reaches the goal);
#   b. one planner container killed (podman kill): plans are still answered, by the other;
#   c. the map server container restarted, then re-created (a new container on the same
#      named volume): every layer is back each time, no version lower;
#   d. the mission executive for r1 planned its first window (and arrived, if in time);
#   e. restart: always: the surviving planner's process is SIGKILLed from the host (a
#      crash; podman does not restart a container it was told to kill): podman restarts
#      it and it answers plans again;
#   e2. the sim's process SIGKILLed: podman restarts it and it resumes its clock and
#      robots from its snapshot (the sim-state volume);
#   f. the router restarted, and the mission executive SIGKILLed while the router is
#      down: plans are answered again and every service is running (the mission restarted).
# Prints PASS/FAIL lines with figures; the stack is always torn down, volumes included,
# and the containers' logs are printed when something fails. Bounded: every wait has a
# timeout and the whole run a deadline (ROAM_CHECK_DEADLINE_S, default 290 s).
#
#   deploy/checks/compose.sh                             builds with cargo (incremental) first
#   ROAM_BIN=target/release/roam deploy/checks/compose.sh   reuse an existing release binary
#
# Needs podman and podman-compose (it installs nothing). Environment: ROAM_BIN,
# ROAM_IMAGE (default roam:latest), ROAM_HOST_PORT (default 7447), ROAM_CHECK_PROJECT
# (default roamcheck), CONTAINERS_CONF (default deploy/containers.conf when runc is
# installed), ROAM_CHECK_SKIP_BUILD=1 (use the existing image).
set -euo pipefail

t_start=$(date +%s.%N)
deadline=$((SECONDS + ${ROAM_CHECK_DEADLINE_S:-290}))
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
deploy="$(cd "$here/.." && pwd)"
repo="$(cd "$deploy/.." && pwd)"
compose_file="$deploy/compose.yaml"
project="${ROAM_CHECK_PROJECT:-roamcheck}"
export ROAM_HOST_PORT="${ROAM_HOST_PORT:-7447}"
export ROAM_IMAGE="${ROAM_IMAGE:-roam:latest}"
# The host-side client talks to the published port only.
unset ZENOH_CONFIG ROAM_ROOT

failures=0
say() { printf '%s\n' "compose.sh: $*" >&2; }
pass() { printf 'PASS %s\n' "$*"; }
fail() { printf 'FAIL %s\n' "$*"; failures=$((failures + 1)); }
# To stderr, so that it shows also from inside a command substitution.
die() { printf 'FAIL %s\n' "$*" >&2; exit 1; }
elapsed() { awk -v a="$1" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }'; }
left() { echo $((deadline - SECONDS)); }
# Appended to a timeout's message when it was the whole run's deadline that ran out.
late() { [ "$(left)" -gt 0 ] || printf ' (the check'"'"'s deadline, %s s, passed)' "${ROAM_CHECK_DEADLINE_S:-290}"; }
# Runs a command with a timeout of at most $1 seconds, never past the deadline.
bounded() {
    local t=$1; shift
    local l; l=$(left)
    [ "$l" -gt 0 ] || die "the check's deadline passed"
    [ "$t" -le "$l" ] || t=$l
    timeout --kill-after=5 "$t" "$@"
}

# ---- prerequisites -------------------------------------------------------------------
command -v podman >/dev/null 2>&1 || die "podman is not installed (apt-get install podman runc netavark aardvark-dns iptables)"
if command -v podman-compose >/dev/null 2>&1; then
    pc=(podman-compose)
else
    die "podman-compose is not installed (pip install podman-compose==1.6.0)"
fi
command -v timeout >/dev/null 2>&1 || die "timeout (coreutils) is needed"
# JSON readers: jq if installed, else python3.
#   field NAME     a top-level field of the object on stdin (true/false as such)
#   ncells         the number of cells of the plan on stdin
#   versions       "name version" per layer of the layer list on stdin
if command -v jq >/dev/null 2>&1; then
    field() { jq -r ".$1"; }
    ncells() { jq -r '.cells | length'; }
    versions() { jq -r '.layers[] | "\(.name) \(.version)"'; }
elif command -v python3 >/dev/null 2>&1; then
    field() { python3 -c 'import json,sys; v = json.load(sys.stdin)[sys.argv[1]]; print(json.dumps(v) if isinstance(v, bool) else v)' "$1"; }
    ncells() { python3 -c 'import json,sys; print(len(json.load(sys.stdin)["cells"]))'; }
    versions() { python3 -c 'import json,sys; [print(l["name"], l["version"]) for l in json.load(sys.stdin)["layers"]]'; }
else
    die "jq or python3 is needed to read JSON"
fi
if [ -z "${CONTAINERS_CONF:-}" ] && command -v runc >/dev/null 2>&1; then
    export CONTAINERS_CONF="$deploy/containers.conf"
fi
say "podman $(podman --version | awk '{print $3}'), $("${pc[@]}" --version 2>/dev/null | awk '/podman-compose/ {print $3}' | head -1 | sed 's/^/podman-compose /'), CONTAINERS_CONF=${CONTAINERS_CONF:-unset}"

pc_run() { bounded "$1" "${pc[@]}" -p "$project" -f "$compose_file" "${@:2}"; }
containers() { timeout 20 podman ps -a --filter "label=io.podman.compose.project=$project" --format '{{.Names}}'; }
container_of() {
    timeout 20 podman ps -a --filter "label=io.podman.compose.project=$project" \
        --filter "label=io.podman.compose.service=$1" --format '{{.Names}}' | head -1
}

teardown() {
    local rc=$?
    set +e
    trap - EXIT INT TERM
    if [ "$rc" -ne 0 ] || [ "$failures" -ne 0 ]; then
        for c in $(containers); do
            echo "----- logs of $c ($(podman inspect -f '{{.State.Status}}, restarts {{.RestartCount}}' "$c" 2>/dev/null)) -----"
            timeout 10 podman logs --tail 60 "$c" 2>&1
        done
    fi
    local t; t=$(date +%s.%N)
    timeout --kill-after=5 60 "${pc[@]}" -p "$project" -f "$compose_file" down -v -t 5 >/dev/null 2>&1
    for c in $(containers); do timeout 20 podman rm -f -t 2 "$c" >/dev/null 2>&1; done
    timeout 20 podman volume rm -f "${project}_map-data" "${project}_sim-state" >/dev/null 2>&1
    say "$project torn down (containers, network, volume) in $(elapsed "$t") s"
    echo "wall time: $(elapsed "$t_start") s"
    [ "$rc" -eq 0 ] && [ "$failures" -ne 0 ] && rc=1
    exit "$rc"
}
trap teardown EXIT
trap 'exit 130' INT TERM

# ---- the image and the host's client -------------------------------------------------
if [ -n "${ROAM_BIN:-}" ]; then
    case "$ROAM_BIN" in /*) roam="$ROAM_BIN" ;; *) roam="$PWD/$ROAM_BIN" ;; esac
else
    roam="$repo/target/release/roam"
fi
if [ "${ROAM_CHECK_SKIP_BUILD:-0}" = 1 ]; then
    podman image exists "$ROAM_IMAGE" || die "ROAM_CHECK_SKIP_BUILD=1 but there is no image $ROAM_IMAGE"
else
    t=$(date +%s.%N)
    build_args=()
    [ -n "${ROAM_BIN:-}" ] && build_args=(--bin "$roam")
    bounded 240 "$deploy/container/build-image.sh" --engine podman --tag "$ROAM_IMAGE" "${build_args[@]}" \
        >/dev/null || die "the image did not build (deploy/container/build-image.sh); with a cold target/, build first or set ROAM_BIN"
    say "image $ROAM_IMAGE built in $(elapsed "$t") s"
fi
[ -x "$roam" ] || die "no roam binary at $roam for the host-side queries (set ROAM_BIN)"
image_mb=$(podman image inspect --format '{{.Size}}' "$ROAM_IMAGE" | awk '{printf "%.1f", $1 / 1e6}')
client=(--mode client --connect "tcp/127.0.0.1:$ROAM_HOST_PORT" --no-multicast)

# ---- up ------------------------------------------------------------------------------
if [ -n "$(containers)" ]; then
    say "removing a previous $project stack"
    pc_run 60 down -v -t 5 >/dev/null 2>&1 || true
fi
if (exec 3<>"/dev/tcp/127.0.0.1/$ROAM_HOST_PORT") 2>/dev/null; then
    die "127.0.0.1:$ROAM_HOST_PORT is already in use on the host; set ROAM_HOST_PORT to a free port"
fi
t_up=$(date +%s.%N)
up_log=$(mktemp)
if ! pc_run 90 up -d >"$up_log" 2>&1; then
    tail -n 40 "$up_log" >&2
    rm -f "$up_log"
    die "podman-compose up failed (its last lines above)"
fi
rm -f "$up_log"
services=(router map-server planner-a planner-b sim localization controller mapper mission)
say "up: ${#services[@]} services in $(elapsed "$t_up") s; waiting for every service to be ready"

# Every service logs `service ready` (the router: `router running`) once its keys are up.
ready_line() {
    case "$1" in router) echo "router running" ;; *) echo "service ready" ;; esac
}
ready_count() { podman logs "$(container_of "$1")" 2>&1 | grep -c "$(ready_line "$1")" || true; }
wait_ready() { # service, seconds, [count]
    local until=$((SECONDS + $2)) want=${3:-1}
    while [ "$(ready_count "$1")" -lt "$want" ]; do
        [ "$SECONDS" -lt "$until" ] && [ "$(left)" -gt 0 ] || return 1
        sleep 0.2
    done
}
for s in "${services[@]}"; do
    wait_ready "$s" 60 || die "$s did not become ready within 60 s$(late)"
done
# ...and the router answers from the host.
until layers_json=$(bounded 5 "$roam" map layers "${client[@]}" --timeout 2 2>/dev/null); do
    [ "$(elapsed "$t_up" | cut -d. -f1)" -lt 60 ] || die "the map server did not answer through 127.0.0.1:$ROAM_HOST_PORT within 60 s"
    sleep 0.3
done
t_live=$(elapsed "$t_up")
say "live: every service ready and answering from the host $t_live s after 'up'"

# ---- a. a plan from outside ----------------------------------------------------------
plan() { # seed -> JSON plan on stdout
    bounded 20 "$roam" plan --start=-8,-8 --goal=6,-7 --budget 80 --generations 300 \
        --deadline 5 --seed "$1" --json --timeout 10 "${client[@]}" 2>/dev/null
}
summary() { # JSON plan on stdin -> one line
    local p; p=$(cat)
    printf 'instance %s, %s cells, reaches goal %s, ETA %.1f s of 80 s, planned in %.0f ms' \
        "$(field instance <<<"$p")" "$(ncells <<<"$p")" \
        "$(field reaches_goal <<<"$p")" "$(field t_eta_s <<<"$p")" "$(field planning_ms <<<"$p")"
}
good_plan() { # JSON plan on stdin: a path that reaches the goal within budget
    local p; p=$(cat)
    [ "$(ncells <<<"$p")" -gt 1 ] && [ "$(field reaches_goal <<<"$p")" = true ] &&
        [ "$(field within_budget <<<"$p")" = true ]
}
if p=$(plan 1) && good_plan <<<"$p"; then
    pass "a. plan from the host through the router: $(summary <<<"$p")"
else
    fail "a. plan from the host through the router: no good plan: ${p:-no answer}"
fi

# ---- b. a planner killed -------------------------------------------------------------
killed=planner-a
bounded 20 podman kill "$(container_of "$killed")" >/dev/null
answered=()
ok=1
for seed in 2 3 4; do
    if p=$(plan "$seed") && good_plan <<<"$p" && [ "$(field instance <<<"$p")" != "$killed" ]; then
        answered+=("$(field instance <<<"$p")")
    else
        ok=0
        answered+=("none")
    fi
done
state=$(podman inspect -f '{{.State.Status}}' "$(container_of "$killed")")
if [ "$ok" = 1 ]; then
    pass "b. $killed killed (podman kill, container $state): 3 of 3 plans answered, by ${answered[*]}"
else
    fail "b. $killed killed (container $state): plans answered by: ${answered[*]}"
fi

# ---- c. the map server restarted, then re-created -------------------------------------
# Versions before, the action, then every layer back with a version not lower. A restart
# keeps the container (and its writable layer); the re-creation gets a new container, so
# only the named volume can have kept the layers.
t_back=""
map_survives() { # label, command...
    local label=$1; shift
    local ms before after after_json="" t figures=() lost=() lower=() name v0 v1 id0 id1
    ms=$(container_of map-server)
    id0=$(podman inspect -f '{{.Id}}' "$ms" | cut -c1-12)
    before=$(bounded 10 "$roam" map layers "${client[@]}" --timeout 5 | versions)
    t=$(date +%s.%N)
    bounded 60 "$@" >/dev/null 2>&1 || { fail "c. map server $label: '$*' failed"; return; }
    until after_json=$(bounded 5 "$roam" map layers "${client[@]}" --timeout 2 2>/dev/null); do
        [ "$(elapsed "$t" | cut -d. -f1)" -lt 30 ] || break
        sleep 0.2
    done
    local back; back=$(elapsed "$t")
    t_back="${t_back:+$t_back, }$label $back s"
    after=""
    [ -n "$after_json" ] && after=$(versions <<<"$after_json")
    id1=$(podman inspect -f '{{.Id}}' "$(container_of map-server)" | cut -c1-12)
    while read -r name v0; do
        [ -n "$name" ] || continue
        v1=$(awk -v n="$name" '$1 == n {print $2}' <<<"$after")
        if [ -z "$v1" ]; then
            lost+=("$name")
        else
            [ "$v1" -ge "$v0" ] || lower+=("$name $v0->$v1")
            figures+=("$name $v0->$v1")
        fi
    done <<<"$before"
    if [ -n "$after" ] && [ ${#lost[@]} -eq 0 ] && [ ${#lower[@]} -eq 0 ]; then
        pass "c. map server $label (container $id0 -> $id1), answering again after $back s; $(wc -l <<<"$before") layers kept, versions not lower: ${figures[*]}"
    else
        fail "c. map server $label (container $id0 -> $id1): lost [${lost[*]}] lower [${lower[*]}] before [$(tr '\n' ' ' <<<"$before")] after [$(tr '\n' ' ' <<<"$after")]"
    fi
}
map_survives restarted podman restart -t 5 "$(container_of map-server)"
map_survives re-created "${pc[@]}" -p "$project" -f "$compose_file" up -d --no-deps --force-recreate map-server

# ---- d. the mission executive for r1 -------------------------------------------------
mission=$(container_of mission)
until podman logs "$mission" 2>&1 | grep -q "planned window=0"; do
    [ "$(elapsed "$t_up" | cut -d. -f1)" -lt 60 ] && [ "$(left)" -gt 0 ] || break
    sleep 0.5
done
# A log line's key=value field.
kv() { tr ' ' '\n' <<<"$1" | awk -F= -v k="$2" '$1 == k {print $2; exit}'; }
planned=$(podman logs "$mission" 2>&1 | grep -m1 "planned window=0" || true)
if [ -n "$planned" ]; then
    what=$(printf 'window 0 planned: task %s, budget %.1f s, ETA %.1f s, curious %s' \
        "$(kv "$planned" task)" "$(kv "$planned" budget_s)" "$(kv "$planned" eta_s)" "$(kv "$planned" curious)")
    # Arrival at goal1 comes about 20 s later at the sim's 2x: wait up to 45 s after up.
    until podman logs "$mission" 2>&1 | grep -q "arrived window=0"; do
        [ "$(elapsed "$t_up" | cut -d. -f1)" -lt 45 ] && [ "$(left)" -gt 0 ] || break
        sleep 0.5
    done
    arrived=$(podman logs "$mission" 2>&1 | grep -m1 "arrived window=0" || true)
    if [ -n "$arrived" ]; then
        what="$what; arrived at sim time $(kv "$arrived" at_s) s for its task at $(kv "$arrived" start_s) s"
    else
        what="$what; not arrived yet (optional)"
    fi
    pass "d. mission executive for r1: $what"
else
    fail "d. mission executive for r1: no 'planned window=0' in its log within 60 s of up$(late)"
fi

# ---- e. restart: always after a crash -------------------------------------------------
survivor=planner-b
sc=$(container_of "$survivor")
pid=$(podman inspect -f '{{.State.Pid}}' "$sc")
r0=$(podman inspect -f '{{.RestartCount}}' "$sc")
t=$(date +%s.%N)
if [ "${pid:-0}" -gt 0 ] && kill -KILL "$pid" 2>/dev/null; then
    if wait_ready "$survivor" 30 2; then
        p=""
        until p=$(plan 5) && good_plan <<<"$p"; do
            [ "$(elapsed "$t" | cut -d. -f1)" -lt 30 ] || break
            sleep 0.3
        done
        r1=$(podman inspect -f '{{.RestartCount}}' "$sc")
        if [ -n "$p" ] && good_plan <<<"$p" && [ "$(field instance <<<"$p")" = "$survivor" ]; then
            pass "e. $survivor's process SIGKILLed: podman restarted it (restarts $r0->$r1), plans answered again by $survivor $(elapsed "$t") s after the crash"
        else
            fail "e. $survivor restarted (restarts $r0->$r1) but no good plan from it: ${p:-no answer}"
        fi
    else
        fail "e. $survivor's process SIGKILLed: not ready again within 30 s$(late) (restarts $(podman inspect -f '{{.RestartCount}}' "$sc"))"
    fi
else
    echo "SKIP e. cannot signal $survivor's process (pid ${pid:-?}) from here"
fi

# ---- e2. the sim world crashes and resumes from its snapshot -----------------------------
simc=$(container_of sim)
pid=$(podman inspect -f '{{.State.Pid}}' "$simc")
r0=$(podman inspect -f '{{.RestartCount}}' "$simc")
t=$(date +%s.%N)
if [ "${pid:-0}" -gt 0 ] && kill -KILL "$pid" 2>/dev/null; then
    resumed=""
    until resumed=$(timeout 10 podman logs "$simc" 2>&1 | grep -m1 "resumed from the snapshot"); do
        [ "$(elapsed "$t" | cut -d. -f1)" -lt 30 ] || break
        sleep 0.3
    done
    r1=$(podman inspect -f '{{.RestartCount}}' "$simc")
    if [ -n "$resumed" ]; then
        step=$(sed -n 's/.*step=\([0-9]*\).*/\1/p' <<<"$resumed")
        pass "e2. the sim's process SIGKILLed: podman restarted it (restarts $r0->$r1) and it resumed from its snapshot at step ${step:-?} (volume sim-state), $(elapsed "$t") s after the crash"
    else
        fail "e2. the sim's process SIGKILLed: no resume from the snapshot within 30 s (restarts $r0->$r1)"
    fi
else
    echo "SKIP e2. cannot signal the sim's process (pid ${pid:-?}) from here"
fi

# ---- f. the router restarted ----------------------------------------------------------
# Every service reconnects by itself; one that exits meanwhile is restarted by podman
# (which would not happen with depends_on: see deploy/compose.yaml).
rt=$(container_of router)
declare -A r0
for s in "${services[@]}"; do r0[$s]=$(podman inspect -f '{{.RestartCount}}' "$(container_of "$s")"); done
t=$(date +%s.%N)
router_pid=$(timeout 10 podman inspect -f '{{.State.Pid}}' "$rt")
bounded 30 podman restart -t 5 "$rt" >/dev/null &
restarting=$!
# A service that dies while the router is down (here the mission executive, SIGKILLed
# from the host) must be restarted all the same: wait until the old router process is
# gone (at most 10 s), then kill it.
for _ in $(seq 200); do
    kill -0 "${router_pid:-0}" 2>/dev/null || break
    sleep 0.05
done
mpid=$(podman inspect -f '{{.State.Pid}}' "$(container_of mission)")
crashed=""
[ "${mpid:-0}" -gt 0 ] && kill -KILL "$mpid" 2>/dev/null && crashed=mission
wait "$restarting" || fail "f. podman restart of the router failed"
p=""
until p=$(plan 6) && good_plan <<<"$p"; do
    [ "$(elapsed "$t" | cut -d. -f1)" -lt 30 ] && [ "$(left)" -gt 0 ] || break
    sleep 0.2
done
t_router=$(elapsed "$t")
not_running() {
    local s st out=()
    for s in "${services[@]}"; do
        [ "$s" = "$killed" ] && continue
        st=$(podman inspect -f '{{.State.Status}}' "$(container_of "$s")")
        [ "$st" = running ] || out+=("$s:$st")
    done
    echo "${out[*]}"
}
# Settle, then every service but the one killed in b must be running (again).
sleep 3
until [ -z "$(not_running)" ]; do
    [ "$(elapsed "$t" | cut -d. -f1)" -lt 30 ] && [ "$(left)" -gt 0 ] || break
    sleep 0.5
done
down=$(not_running)
restarted=()
for s in "${services[@]}"; do
    r1=$(podman inspect -f '{{.RestartCount}}' "$(container_of "$s")")
    [ "$r1" = "${r0[$s]}" ] || restarted+=("$s(+$((r1 - r0[$s])))")
done
mission_back=1
[ -n "$crashed" ] && [[ " ${restarted[*]} " != *" mission(+"* ]] && mission_back=0
if [ -n "$p" ] && good_plan <<<"$p" && [ -z "$down" ] && [ "$mission_back" = 1 ]; then
    pass "f. router restarted${crashed:+, $crashed SIGKILLed meanwhile}: plans answered again $t_router s later (by $(field instance <<<"$p")); every service running; restarted by podman: ${restarted[*]:-none}"
else
    fail "f. router restarted: plan ${p:+answered}${p:-not answered} after $t_router s; not running: [${down}]; restarted: ${restarted[*]:-none}"
fi

echo "figures: image $ROAM_IMAGE $image_mb MB; stack live $t_live s after starting 'up'; map server answering again: $t_back; plans again $t_router s after the router's restart began"
if [ "$failures" -eq 0 ]; then
    echo "all checks passed"
else
    echo "$failures check(s) failed"
fi
