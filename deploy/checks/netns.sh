#!/usr/bin/env bash
# roam on several hosts: four network namespaces on one bridge, every service a Zenoh
# client of one router, multicast off. Run as root from anywhere:
#
#     sudo deploy/checks/netns.sh
#
# Hosts (10.231.7.0/24, one veth each into a bridge in a fifth "switch" namespace):
#   router  10.231.7.10  roam router, map server, sim (config/scenarios/fleet.yaml, 3x
#                        real time), localization, and the probe that records the robots
#   planner 10.231.7.20  planners p1 p2, mission executives for r1 and r2
#   robot1  10.231.7.31  roam controller --robot r1 (on board r1; its body is simulated
#                        on the router host)
#   robot2  10.231.7.32  roam controller --robot r2
#
# Checks (each prints PASS or FAIL with its figure; the exit status is 1 on any FAIL):
#   1. every service is up (its liveliness token) and both missions start;
#   2. robot1's link is cut for 5 s while both robots drive: r1 stops, its controller
#      logs that it holds the robot on stale estimates, r2 keeps driving;
#   3. after the link returns r1 drives again and both missions complete (every task
#      arrived);
#   4. the router is killed and started again: every service's token comes back by
#      itself and a plan asked from the planner host is answered.
#
# Environment: ROAM_BIN (default target/release/roam), NETNS_CUT_S (the cut, default 5
# s), NETNS_OUT (log directory, default a new /tmp/roam-netns.XXXXXX). The whole run is
# bounded at 235 s; a trap always kills every process it started and deletes every
# namespace (and so every veth and the bridge) it made, and on failure prints the last
# lines of every log.
set -euo pipefail

HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
REPO=$(cd "$HERE/../.." && pwd)
ROAM=${ROAM_BIN:-$REPO/target/release/roam}
PROBE=$HERE/netns/probe.py
SCENARIO=$REPO/config/scenarios/fleet.yaml
CLIENT_CFG=$REPO/deploy/client.json5
ROUTER_CFG=$REPO/deploy/router.json5
CONTROLLER_CFG=$HERE/netns/controller.yaml
OUT=${NETNS_OUT:-$(mktemp -d /tmp/roam-netns.XXXXXX)}
mkdir -p "$OUT"

NET=10.231.7
declare -A IP=([router]=$NET.10 [planner]=$NET.20 [robot1]=$NET.31 [robot2]=$NET.32)
EP=tcp/${IP[router]}:7447
TAG=roamnet$$
SW=$TAG-sw
HOSTS=(router planner robot1 robot2)
RATE=3          # the sim's real-time factor
CUT_S=${NETNS_CUT_S:-5}  # how long robot1's link is down
STALE_S=$(awk '/^stale_after_s:/ {print $2}' "$CONTROLLER_CFG")
BOUND_S=235     # the whole run, seconds

T0=$(date +%s.%N)
declare -A PIDS=()
NAMESPACES=()
FAILS=0
WATCHDOG=
NAP=

now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN {printf "%.2f", b - a}'; }
# within S: true while less than S seconds have passed since the start.
within() { awk -v a="$T0" -v b="$(now)" -v s="$1" 'BEGIN {exit !(b - a < s)}'; }
say() { printf '[%6.1fs] %s\n' "$(since "$T0")" "$*"; }
pass() { printf 'PASS  %s\n' "$*"; }
fail() { printf 'FAIL  %s\n' "$*"; FAILS=$((FAILS + 1)); }
# A sleep the traps interrupt at once (bash runs a trap only after a foreground command).
nap() { sleep "$1" & NAP=$!; wait "$NAP"; NAP=; }
ns() { echo "$TAG-$1"; }

cleanup() {
    local rc=$?
    set +e
    trap - EXIT INT TERM
    if [[ -n $WATCHDOG ]]; then
        pkill -TERM -P "$WATCHDOG" 2>/dev/null
        kill -TERM "$WATCHDOG" 2>/dev/null
    fi
    [[ -n $NAP ]] && kill -TERM "$NAP" 2>/dev/null
    local name pid
    for name in "${!PIDS[@]}"; do kill -TERM "${PIDS[$name]}" 2>/dev/null; done
    for _ in $(seq 30); do
        local alive=0
        for pid in "${PIDS[@]}"; do kill -0 "$pid" 2>/dev/null && alive=1; done
        ((alive)) || break
        sleep 0.1
    done
    for name in "${!PIDS[@]}"; do
        if kill -0 "${PIDS[$name]}" 2>/dev/null; then
            echo "$name did not stop within 3 s of SIGTERM: SIGKILL"
            kill -KILL "${PIDS[$name]}" 2>/dev/null
            wait "${PIDS[$name]}" 2>/dev/null
        fi
    done
    # Anything else still inside our namespaces was started by this script.
    for n in "${NAMESPACES[@]}"; do
        for pid in $(ip netns pids "$n" 2>/dev/null); do kill -KILL "$pid" 2>/dev/null; done
    done
    for n in "${NAMESPACES[@]}"; do ip netns del "$n" 2>/dev/null; done
    if ((rc != 0 || FAILS > 0)); then
        echo
        echo "---- last lines of each log ($OUT) ----"
        local f
        for f in "$OUT"/*.log; do
            [[ -e $f ]] || continue
            echo "== $(basename "$f")"
            tail -n 12 "$f"
        done
    fi
    if ((rc == 0 && FAILS == 0)) && [[ -z ${NETNS_OUT:-} ]]; then
        rm -rf "$OUT"
        echo "wall time: $(since "$T0") s"
    else
        echo "logs: $OUT   wall time: $(since "$T0") s"
    fi
    if ((rc == 0 && FAILS > 0)); then rc=1; fi
    exit "$rc"
}
trap cleanup EXIT
trap 'echo "interrupted"; exit 130' INT
trap 'echo "stopped (bound of ${BOUND_S} s or SIGTERM)"; exit 124' TERM

[[ $(id -u) == 0 ]] || { echo "netns.sh needs root (ip netns)"; exit 2; }
[[ -x $ROAM ]] || { echo "no roam binary at $ROAM: cargo build --release -p roam"; exit 2; }
python3 -c 'import zenoh' 2>/dev/null \
    || { echo "needs the Python Zenoh client: pip install eclipse-zenoh==1.10.2"; exit 2; }

(sleep "$BOUND_S" && kill -TERM $$) 2>/dev/null &
WATCHDOG=$!
disown "$WATCHDOG"

# ---- topology -------------------------------------------------------------------------
ip netns add "$SW"; NAMESPACES+=("$SW")
ip -n "$SW" link add br0 type bridge
ip -n "$SW" link set br0 up
for h in "${HOSTS[@]}"; do
    ip netns add "$(ns "$h")"; NAMESPACES+=("$(ns "$h")")
    ip -n "$SW" link add "$h" type veth peer name eth0 netns "$(ns "$h")"
    ip -n "$SW" link set "$h" master br0
    ip -n "$SW" link set "$h" up
    ip -n "$(ns "$h")" addr add "${IP[$h]}/24" dev eth0
    ip -n "$(ns "$h")" link set eth0 up
    ip -n "$(ns "$h")" link set lo up
done
say "hosts: router ${IP[router]}, planner ${IP[planner]}, robot1 ${IP[robot1]}, robot2 ${IP[robot2]} (namespaces $TAG-*)"

# start NAME HOST CMD...: a process on a host, logging to $OUT/NAME.log.
start() {
    local name=$1 host=$2; shift 2
    ip netns exec "$(ns "$host")" env NO_COLOR=1 "$@" >"$OUT/$name.log" 2>&1 &
    PIDS[$name]=$!
}
# service NAME HOST ROLE ARGS...: a roam service in client mode (deploy/client.json5).
service() {
    local name=$1 host=$2; shift 2
    start "$name" "$host" ZENOH_CONFIG="$CLIENT_CFG" "$ROAM" "$@" --connect "$EP"
}
live_wait() { # live_wait HOST SECONDS KEY...: waits for liveliness tokens
    local host=$1 wait=$2; shift 2
    local args=() k
    for k in "$@"; do args+=(--expect "roam/@live/$k"); done
    timeout $((${wait%.*} + 10)) \
        ip netns exec "$(ns "$host")" python3 "$PROBE" live --connect "$EP" --wait "$wait" "${args[@]}"
}
router_listening() {
    ip netns exec "$(ns planner)" timeout 1 bash -c "exec 3<>/dev/tcp/${IP[router]}/7447" 2>/dev/null
}
start_router() {
    start "router$1" router ZENOH_CONFIG="$ROUTER_CFG" "$ROAM" router
    local i
    for i in $(seq 50); do router_listening && return 0; sleep 0.1; done
    return 1
}
count() { grep -c -- "$1" "$2" 2>/dev/null || true; }

# ---- 1. services up, missions started ---------------------------------------------------
start_router ""
say "router listening on $EP"
service map-server router map-server --map "$SCENARIO" --instance main
service localization router localization --scenario "$SCENARIO" --instance main
live_wait router 20 map-server/main localization/main >"$OUT/live-1.txt" || true
service planner-p1 planner planner --instance p1
service planner-p2 planner planner --instance p2
service controller-r1 robot1 controller --config "$CONTROLLER_CFG" --scenario "$SCENARIO" --robot r1 --instance r1
service controller-r2 robot2 controller --config "$CONTROLLER_CFG" --scenario "$SCENARIO" --robot r2 --instance r2
live_wait router 20 planner/p1 planner/p2 controller/r1 controller/r2 >"$OUT/live-2.txt" || true
# The sim last, so that the missions' clock starts with them.
service sim router sim --scenario "$SCENARIO" --rate "$RATE" --instance main
start recorder router python3 "$PROBE" record --connect "$EP" --out "$OUT/record.jsonl"
live_wait router 20 sim/main >"$OUT/live-3.txt" || true
service mission-r1 planner mission --config "$HERE/netns/mission-r1.yaml" --instance r1
service mission-r2 planner mission --config "$HERE/netns/mission-r2.yaml" --instance r2

ALL_TOKENS=(map-server/main localization/main sim/main planner/p1 planner/p2
    controller/r1 controller/r2 mission/r1 mission/r2)
if live_wait router 30 "${ALL_TOKENS[@]}" >"$OUT/live-up.txt"; then
    tokens_up=1
else
    tokens_up=0
fi
planned=0
for _ in $(seq 300); do
    planned=$(($(count 'planned window=0' "$OUT/mission-r1.log") > 0 && $(count 'planned window=0' "$OUT/mission-r2.log") > 0))
    ((planned)) && break
    sleep 0.1
done
UP_S=$(since "$T0")
if ((tokens_up && planned)); then
    pass "1. all 9 services up (tokens: $(grep -c '^roam/@live/' "$OUT/live-up.txt")) and both missions planned window 0, ${UP_S} s after the start"
else
    fail "1. services up: tokens $( ((tokens_up)) && echo all || echo "missing: $(tail -n 1 "$OUT/live-up.txt")"), missions planned: $planned"
    exit 1
fi

# ---- 2. cut robot1's link while both robots drive --------------------------------------
# analyse MODE ARGS: answers from the probe's record of the robots (netns/analyse.py).
analyse() { python3 "$HERE/netns/analyse.py" "$OUT/record.jsonl" "$@"; }

driving=0
for _ in $(seq 200); do
    [[ $(analyse driving) == 1 ]] && { driving=1; break; }
    sleep 0.1
done
if ((driving)); then
    say "both robots driving; cutting robot1's link (switch port robot1 down) for ${CUT_S} s"
else
    say "the robots were not both driving within 20 s; cutting robot1's link anyway for ${CUT_S} s"
fi
T_CUT=$(now)
ip -n "$SW" link set robot1 down
nap "$CUT_S"
ip -n "$SW" link set robot1 up
T_UP=$(now)
say "robot1's link is back"
nap 3

read -r HALT_S SETTLED_M R2_M R1_SAMPLES R1_BEFORE_M < <(analyse cut "$T_CUT" "$T_UP" "$STALE_S")
halt_log=$(sed -n 's/^\([0-9T:.-]*Z\) .*no estimate for .*holding the robot.*/\1/p' "$OUT/controller-r1.log" | tail -n 1)
HELD_S=$(python3 -c '
import sys, datetime
ts, t_cut = sys.argv[1], float(sys.argv[2])
if not ts:
    print("none"); sys.exit()
t = datetime.datetime.strptime(ts[:26], "%Y-%m-%dT%H:%M:%S.%f").replace(tzinfo=datetime.timezone.utc).timestamp()
print(f"{t - t_cut:.2f}" if t >= t_cut else "none")' "$halt_log" "$T_CUT")
r2_held=$(count 'holding the robot' "$OUT/controller-r2.log")
HALT_LIMIT=$(awk -v s="$STALE_S" -v r="$RATE" 'BEGIN {printf "%.2f", s + 0.4 / r}')
if awk -v h="$HALT_S" -v l="$HALT_LIMIT" -v s="$SETTLED_M" -v n="$R1_SAMPLES" \
    'BEGIN {exit !(h <= l && s < 0.02 && n >= 10)}'; then
    pass "2a. r1 stopped ${HALT_S} s after the cut (limit: stale_after_s ${STALE_S} s + one sim step) and moved ${SETTLED_M} m for the rest of the cut (${R1_SAMPLES} sim steps seen from the router host; ${R1_BEFORE_M} m in the second before the cut)"
else
    fail "2a. r1 after the cut: last move ${HALT_S} s after it (limit ${HALT_LIMIT} s), ${SETTLED_M} m after stale_after_s, ${R1_SAMPLES} steps seen"
fi
# The watchdog counts from the last estimate, which came up to one sim step before the
# cut, and looks every stale_after_s / 4.
HELD_MIN=$(awk -v s="$STALE_S" -v r="$RATE" 'BEGIN {printf "%.2f", s - 0.4 / r - 0.05}')
HELD_MAX=$(awk -v s="$STALE_S" 'BEGIN {printf "%.2f", s * 1.25 + 0.5}')
if [[ $HELD_S != none ]] && awk -v h="$HELD_S" -v a="$HELD_MIN" -v b="$HELD_MAX" 'BEGIN {exit !(h >= a && h <= b)}'; then
    pass "2b. the r1 controller logged 'no estimate ... holding the robot' ${HELD_S} s after the cut (stale_after_s ${STALE_S} s; accepted ${HELD_MIN}-${HELD_MAX} s)"
else
    fail "2b. the r1 controller's stale-estimate hold: logged ${HELD_S} s after the cut (accepted ${HELD_MIN}-${HELD_MAX} s)"
fi
# r2's distance is the measure; a hold of r2 (a stall of its estimates on a loaded
# machine) is reported, not failed, since it says nothing about r1's link.
if awk -v d="$R2_M" 'BEGIN {exit !(d > 2.0)}'; then
    pass "2c. r2 drove ${R2_M} m during the ${CUT_S} s cut (threshold 2 m; its controller held it ${r2_held} times in the whole run)"
else
    fail "2c. r2 drove ${R2_M} m during the cut (threshold 2 m), its controller held it ${r2_held} times"
fi

# ---- 3. r1 drives again, both missions complete ----------------------------------------
reports_done=0
while within 200; do
    r1n=$(analyse reports | awk '$1 == "r1" {print $3}')
    r2n=$(analyse reports | awk '$1 == "r2" {print $3}')
    if [[ ${r1n:-0} == 2 && ${r2n:-0} == 2 ]]; then reports_done=1; break; fi
    if (($(count 'gave up' "$OUT/mission-r1.log") + $(count 'gave up' "$OUT/mission-r2.log") > 0)); then break; fi
    sleep 0.5
done
RESUME_S=$(analyse resume "$T_UP")
arrived_logs="r1 $(count ' arrived ' "$OUT/mission-r1.log"), r2 $(count ' arrived ' "$OUT/mission-r2.log")"
MISSIONS_S=$(since "$T0")
if [[ $RESUME_S != none ]] && ((reports_done)); then
    pass "3. r1 drove again ${RESUME_S} s after the link returned; both missions complete ${MISSIONS_S} s after the start (arrived lines: $arrived_logs)"
else
    fail "3. r1 drove again: ${RESUME_S} s after the link returned; missions complete: $reports_done (arrived lines: $arrived_logs)"
fi
analyse reports | sed 's/^/      /'

# ---- 4. restart the router ----------------------------------------------------------------
say "killing the router (SIGKILL), starting it again 1 s later"
kill -KILL "${PIDS[router]}"
wait "${PIDS[router]}" 2>/dev/null || true
sleep 1
T_RESTART=$(now)
if start_router 2; then
    say "router listening again"
else
    fail "4. the router did not listen again within 5 s"
    exit 1
fi
if live_wait router 60 "${ALL_TOKENS[@]}" >"$OUT/live-restart.txt"; then
    at=$(sed -n 's/.*(at \([0-9.]*\)).*/\1/p' "$OUT/live-restart.txt")
    RECONNECT_S=$(awk -v a="$at" -v b="$T_RESTART" 'BEGIN {printf "%.2f", a - b}')
    tokens_back=1
else
    RECONNECT_S=none
    tokens_back=0
fi
plan_out=$(timeout 30 ip netns exec "$(ns planner)" env NO_COLOR=1 ZENOH_CONFIG="$CLIENT_CFG" \
    "$ROAM" plan --connect "$EP" --start=-8,-8 --goal=-2,4 --budget 60 --generations 200 \
    --deadline 2 --timeout 10 2>&1) && plan_ok=1 || plan_ok=0
echo "$plan_out" >"$OUT/plan-after-restart.txt"
# Not a check, a figure: the probe on the router host is a Zenoh client too (Python);
# when does the sim's ground truth reach it again?
FLOW_S=$(analyse flow "$T_RESTART")
plan_line=$(head -n 1 <<<"$plan_out")
if ((tokens_back && plan_ok)); then
    pass "4. after the router restart all 9 tokens were back in ${RECONNECT_S} s (from the new router's start), and a plan from the planner host was answered: $plan_line; the sim's ground truth reached the probe again ${FLOW_S} s after the restart"
else
    fail "4. after the router restart: tokens back: $tokens_back ($(tail -n 1 "$OUT/live-restart.txt")), plan answered: $plan_ok ($plan_line)"
fi

echo
if ((FAILS == 0)); then
    echo "netns check: all PASS (wall time $(since "$T0") s)"
else
    echo "netns check: $FAILS FAIL"
fi
