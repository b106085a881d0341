#!/usr/bin/env python3
"""Reads the netns check's record (probe.py record: one JSON line per sample, with the
wall time `t` it arrived) and answers the check's questions, one mode per question.
Standard library only.

    analyse.py RECORD driving                 1 when r1 and r2 both drive, else 0
    analyse.py RECORD cut T_CUT T_UP STALE    r1's halt time, r1's later motion, r2's
                                              distance, r1's samples, r1's last second
    analyse.py RECORD resume T_UP             seconds until r1 moves after T_UP, or none
    analyse.py RECORD reports                 per robot: reports, arrivals, details
    analyse.py RECORD flow T                  seconds until ground truth flows after T
"""
import json, math, sys
path, mode, *args = sys.argv[1:]
rows = []
with open(path) as f:
    for line in f:
        try:
            rows.append(json.loads(line))
        except ValueError:
            pass
truth = {}
for r in rows:
    if r.get("k") == "truth":
        truth.setdefault(r["r"], []).append((r["t"], r["at"]))
EPS = 0.005   # m per step: no command, no move (the sim adds no noise to a zero command)
def moves(robot):
    s = truth.get(robot, [])
    return [(t1, math.dist(a0, a1)) for (t0, a0), (t1, a1) in zip(s, s[1:])]
if mode == "driving":
    # Both robots have driven at least 0.5 m and moved in the last second.
    ok = True
    for robot in ("r1", "r2"):
        s = truth.get(robot, [])
        if not s:
            ok = False
            continue
        gone = math.dist(s[0][1], s[-1][1])
        recent = sum(d for t, d in moves(robot) if t > s[-1][0] - 1.0)
        ok = ok and gone > 0.5 and recent > 0.05
    print(1 if ok else 0)
elif mode == "cut":
    t_cut, t_up, stale = map(float, args)
    m1 = [(t, d) for t, d in moves("r1") if t_cut <= t <= t_up]
    moving = [t for t, d in m1 if d > EPS]
    halt = max(0.0, (max(moving) - t_cut) if moving else 0.0)
    settled = sum(d for t, d in m1 if t > t_cut + stale + 0.3)
    r2 = sum(d for t, d in moves("r2") if t_cut <= t <= t_up)
    before = sum(d for t, d in moves("r1") if t_cut - 1.0 <= t < t_cut)
    print(f"{halt:.2f} {settled:.3f} {r2:.2f} {len(m1)} {before:.2f}")
elif mode == "resume":
    t_up = float(args[0])
    later = [t for t, d in moves("r1") if t > t_up and d > EPS]
    print(f"{later[0] - t_up:.2f}" if later else "none")
elif mode == "reports":
    reports = [r["body"] for r in rows if r.get("k") == "report"]
    for robot in ("r1", "r2"):
        mine = sorted((b for b in reports if b["robot"] == robot), key=lambda b: b["window"])
        arrived = sum(1 for b in mine if b.get("arrival_s") is not None)
        detail = "; ".join(
            f"{b['task']} arrived {b['arrival_s']:.0f} s (start {b['task_start_s']:.0f} s"
            f"{', on time' if b['on_time'] else ', late'}), replans {b['replans']}"
            + (f" [{', '.join(b['replan_reasons'])}]" if b['replan_reasons'] else "")
            if b.get("arrival_s") is not None else f"{b['task']} not arrived"
            for b in mine)
        print(f"{robot} {len(mine)} {arrived} {detail}")
elif mode == "flow":
    t = float(args[0])
    after = [r["t"] for r in rows if r.get("k") == "truth" and r["t"] > t]
    print(f"{after[0] - t:.2f}" if after else "none")
