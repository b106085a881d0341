#!/usr/bin/env python3
"""The netns check's Zenoh probe (standard library + eclipse-zenoh==1.10.2).

The roam CLI has no client for liveliness or for watching robots, so the check uses this:

    probe.py live   --connect E [--expect KEY]... [--wait S]
        A liveliness `get` on <root>/@live/**; prints one key per line. With --expect,
        repeats until every expected key is there (or --wait seconds pass) and prints
        `all N expected tokens after T s (at UNIX-TIME)`; exit 1 when some are missing.
    probe.py record --connect E --out FILE
        Subscribes to <root>/robot/*/{truth,controller,mission_report} and appends one
        JSON line per sample with the wall time it arrived (`t`, Unix seconds), until
        SIGTERM or SIGINT.
    probe.py status --connect E
        The sim's status (`sim_control` {op: status}) as JSON.

Every session is a client of the router, multicast off, waiting for the router.
"""
import argparse
import json
import signal
import sys
import threading
import time

import zenoh


def session(endpoint):
    config = zenoh.Config()
    config.insert_json5("mode", '"client"')
    config.insert_json5("connect/endpoints", json.dumps([endpoint]))
    config.insert_json5("connect/timeout_ms", "-1")
    config.insert_json5("scouting/multicast/enabled", "false")
    return zenoh.open(config)


def body(payload):
    message = json.loads(payload.to_bytes())
    return message.get("kind"), message.get("body")


def live_keys(s, root, timeout):
    replies = s.liveliness().get(f"{root}/@live/**", timeout=timeout)
    return sorted({str(r.ok.key_expr) for r in replies if r.ok is not None})


def cmd_live(args):
    started = time.monotonic()
    s = session(args.connect)
    try:
        expect = set(args.expect)
        while True:
            keys = live_keys(s, args.root, 2.0)
            missing = sorted(expect - set(keys))
            elapsed = time.monotonic() - started
            if not missing:
                for k in keys:
                    print(k)
                if expect:
                    print(f"all {len(expect)} expected tokens after {elapsed:.2f} s (at {time.time():.3f})")
                return 0
            if elapsed > args.wait:
                for k in keys:
                    print(k)
                print(f"missing after {elapsed:.1f} s: {' '.join(missing)}")
                return 1
            time.sleep(0.2)
    finally:
        s.close()


def cmd_record(args):
    out = open(args.out, "a", buffering=1)
    lock = threading.Lock()
    done = threading.Event()

    def write(record):
        line = json.dumps(record, separators=(",", ":"))
        with lock:
            out.write(line + "\n")

    def on_sample(sample):
        t = time.time()
        key = str(sample.key_expr)
        parts = key.split("/")
        try:
            kind, b = body(sample.payload)
        except (ValueError, UnicodeDecodeError):
            return
        robot, topic = parts[-2], parts[-1]
        if topic == "truth":
            write({"t": t, "k": "truth", "r": robot, "step": b["step"],
                   "sim_t": b["time_s"], "at": b["at"]})
        elif topic == "controller":
            write({"t": t, "k": "ctl", "r": robot, "state": b.get("state"),
                   "mission": b.get("mission")})
        elif topic == "mission_report":
            write({"t": t, "k": "report", "r": robot, "body": b})

    signal.signal(signal.SIGTERM, lambda *_: done.set())
    signal.signal(signal.SIGINT, lambda *_: done.set())
    s = session(args.connect)
    subs = [s.declare_subscriber(f"{args.root}/robot/*/{topic}", on_sample)
            for topic in ("truth", "controller", "mission_report")]
    write({"t": time.time(), "k": "start"})
    done.wait()
    for sub in subs:
        sub.undeclare()
    s.close()
    out.close()
    return 0


def cmd_status(args):
    s = session(args.connect)
    try:
        request = json.dumps({"v": 1, "kind": "sim_control", "body": {"op": "status"}})
        for reply in s.get(f"{args.root}/sim/control", payload=request, timeout=5.0):
            if reply.ok is not None:
                print(json.dumps(body(reply.ok.payload)[1]))
                return 0
            print(f"error: {reply.err.payload.to_string()}", file=sys.stderr)
            return 2
        print("no reply", file=sys.stderr)
        return 3
    finally:
        s.close()


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("command", choices=("live", "record", "status"))
    p.add_argument("--connect", required=True)
    p.add_argument("--root", default="roam")
    p.add_argument("--expect", action="append", default=[])
    p.add_argument("--wait", type=float, default=0.0)
    p.add_argument("--out")
    args = p.parse_args(argv)
    zenoh.init_log_from_env_or("error")
    return {"live": cmd_live, "record": cmd_record, "status": cmd_status}[args.command](args)


if __name__ == "__main__":
    sys.exit(main())
