#!/usr/bin/env python3
"""A stranger's oversized queries against a running roam stack (eclipse-zenoh only).

For each key given, sends AT_ONCE queries of BYTES bytes at once from one session, waits
for their replies, then asks the service a small query from a new session (a client that
did nothing wrong), again until it answers or AFTER_S have passed. Prints one JSON
object: for each key, how many of the big queries were answered (with the refusals'
messages), how many ended with no reply before their timeout (a router that drops an
oversized query ends it with Zenoh's final reply), the slowest query's seconds, whether
the small query was answered and after how many seconds.

    python3 oversized.py --connect tcp/127.0.0.1:7447 --bytes 48000000 KEY...
"""
import argparse
import json
import threading
import time

import zenoh

AT_ONCE = 4
TIMEOUT_S = 60.0
AFTER_S = 5.0


def ask(session, key, payload):
    """The first reply ({'ok': ...}), or {'ended': True} when the query ended without
    one before its timeout, or None when it timed out; with the seconds it took."""
    started = time.monotonic()
    for reply in session.get(key, payload=payload, timeout=TIMEOUT_S):
        took = time.monotonic() - started
        if reply.ok is not None:
            return {'ok': True, 's': took}
        return {'ok': False, 'error': reply.err.payload.to_string()[:300], 's': took}
    took = time.monotonic() - started
    return {'ended': True, 's': took} if took < TIMEOUT_S - 1.0 else None


def open_session(endpoint):
    conf = zenoh.Config()
    conf.insert_json5('mode', '"client"')
    conf.insert_json5('connect/endpoints', json.dumps([endpoint]))
    conf.insert_json5('scouting/multicast/enabled', 'false')
    return zenoh.open(conf)


def answered_after(endpoint, key):
    """Seconds until a new session's small query to KEY is answered, or None."""
    started = time.monotonic()
    # The router may still be draining the flood: connecting counts in the time.
    bystander = None
    while bystander is None:
        try:
            bystander = open_session(endpoint)
        except zenoh.ZError:
            if time.monotonic() - started >= AFTER_S:
                return None
            time.sleep(0.2)
    try:
        while time.monotonic() - started < AFTER_S:
            remaining = AFTER_S - (time.monotonic() - started)
            for _ in bystander.get(key, payload=b'{}', timeout=max(0.5, min(2.0, remaining))):
                return round(time.monotonic() - started, 3)
            time.sleep(0.1)
        return None
    finally:
        bystander.close()


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument('--connect', required=True)
    parser.add_argument('--bytes', type=int, default=48_000_000)
    parser.add_argument('keys', nargs='+')
    args = parser.parse_args()
    session = open_session(args.connect)
    payload = b'x' * args.bytes
    out = {}
    for key in args.keys:
        answers = [None] * AT_ONCE

        def one(i, key=key):
            answers[i] = ask(session, key, payload)

        threads = [threading.Thread(target=one, args=(i,)) for i in range(AT_ONCE)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        after_s = answered_after(args.connect, key)
        replies = [a for a in answers if a is not None and 'ended' not in a]
        out[key] = {'sent': AT_ONCE, 'answered': len(replies),
                    'ended_without_reply': sum(a is not None and 'ended' in a for a in answers),
                    'slowest_s': max((a['s'] for a in answers if a is not None), default=None),
                    'refusals': [a['error'] for a in replies if not a['ok']],
                    'answered_after': after_s is not None, 'after_s': after_s}
    session.close()
    print(json.dumps(out))


if __name__ == '__main__':
    main()
