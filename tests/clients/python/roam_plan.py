#!/usr/bin/env python3
"""Ask a running roam stack for a curious plan over Zenoh (standard library + zenoh).

Install the one dependency, then point the script at a roam router or stack:

    pip install eclipse-zenoh==1.10.2
    roam stack --listen tcp/127.0.0.1:7447 &
    python3 roam_plan.py --connect tcp/127.0.0.1:7447 --start=-8,-8 --goal=6,-7 --budget 80

It finds planner instances through `<root>/@live/planner/*`, sends the plan request to
the first one (or to `<root>/planner/plan` when none is live) and prints a one-line
summary, or the plan body with --json. Exit codes: 0 a plan, 2 an error reply (printed
as `error <code>: <message>` on stderr), 3 no reply in time, 1 anything else.
"""
import argparse
import json
import sys

import zenoh

MODELS = ("shortest", "model0", "model1", "model2", "greedy", "anytime")


def point(text):
    try:
        x, y = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected X,Y, got {text!r}")
    return [x, y]


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--connect", required=True, help="Zenoh endpoint, e.g. tcp/127.0.0.1:7447")
    p.add_argument("--root", default="roam", help="key root (default: roam)")
    p.add_argument("--start", type=point, required=True, help="X,Y in metres")
    p.add_argument("--goal", type=point, required=True, help="X,Y in metres")
    p.add_argument("--budget", type=float, required=True, help="time budget t_exec in seconds")
    p.add_argument("--model", choices=MODELS, default="model1")
    p.add_argument("--deadline", type=float, default=5.0, help="planning deadline in seconds")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--generations", type=int, help="override the GA's max_generations")
    p.add_argument("--json", action="store_true", help="print the whole plan body as JSON")
    return p.parse_args(argv)


def decode(payload, kind):
    """The body of a roam envelope `{"v": 1, "kind": kind, "body": {...}}`."""
    message = json.loads(payload.to_bytes())
    if message.get("v") != 1:
        raise ValueError(f"unsupported protocol version {message.get('v')!r}")
    if message.get("kind") != kind:
        raise ValueError(f"expected a {kind!r} message, got {message.get('kind')!r}")
    return message["body"]


def main(argv=None):
    args = parse_args(argv)
    config = zenoh.Config()
    config.insert_json5("mode", '"client"')
    config.insert_json5("connect/endpoints", json.dumps([args.connect]))
    config.insert_json5("scouting/multicast/enabled", "false")
    body = {"start": args.start, "goal": args.goal, "t_exec_s": args.budget,
            "deadline_s": args.deadline, "model": args.model, "seed": args.seed}
    if args.generations is not None:
        body["params"] = {"max_generations": args.generations}
    request = json.dumps({"v": 1, "kind": "plan_request", "body": body})

    try:
        session = zenoh.open(config)
    except zenoh.ZError as e:
        print(f"cannot connect to {args.connect}: {e}", file=sys.stderr)
        return 1
    try:
        live = session.liveliness().get(f"{args.root}/@live/planner/*", timeout=5)
        instances = sorted({str(r.ok.key_expr).rsplit("/", 1)[-1] for r in live if r.ok})
        if instances:
            key = f"{args.root}/planner/instance/{instances[0]}/plan"
        else:
            key = f"{args.root}/planner/plan"
        for reply in session.get(key, payload=request, timeout=args.deadline + 10):
            if reply.ok is not None:
                plan = decode(reply.ok.payload, "plan")
                if args.json:
                    print(json.dumps(plan, indent=2))
                else:
                    print(f"{plan['model']}: {len(plan['cells'])} cells, "
                          f"ETA {plan['t_eta_s']:.1f} s of {args.budget:g} s budget, "
                          f"reaches goal {str(plan['reaches_goal']).lower()}, "
                          f"distinct information {plan['distinct_information']:.1f}, "
                          f"instance {plan['instance']}")
                return 0
            error = decode(reply.err.payload, "error")
            print(f"error {error.get('code')}: {error.get('message')}", file=sys.stderr)
            return 2
        print(f"no reply from {key} (waited at most {args.deadline + 10:g} s)", file=sys.stderr)
        return 3
    except ValueError as e:  # a reply that is not a roam message of the expected kind
        print(f"bad reply: {e}", file=sys.stderr)
        return 1
    finally:
        session.close()


if __name__ == "__main__":
    sys.exit(main())
