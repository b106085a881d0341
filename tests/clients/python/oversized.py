#!/usr/bin/env python3
"""A stranger's oversized queries against a running roam stack (eclipse-zenoh only).

For each key given, sends AT_ONCE queries of BYTES bytes at once from one session, waits
for their replies, then sends one small query to see that the service still answers.
Prints one JSON object: for each key, how many of the big queries were answered (with
the refusals' messages) and whether the small query after them was.

    python3 oversized.py --connect tcp/127.0.0.1:7447 --bytes 48000000 KEY...
"""
import argparse
import json
import threading

import zenoh

AT_ONCE = 4
TIMEOUT_S = 30.0


def ask(session, key, payload):
    for reply in session.get(key, payload=payload, timeout=TIMEOUT_S):
        if reply.ok is not None:
            return {'ok': True}
        return {'ok': False, 'error': reply.err.payload.to_string()[:300]}
    return None


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument('--connect', required=True)
    parser.add_argument('--bytes', type=int, default=48_000_000)
    parser.add_argument('keys', nargs='+')
    args = parser.parse_args()
    conf = zenoh.Config()
    conf.insert_json5('mode', '"client"')
    conf.insert_json5('connect/endpoints', json.dumps([args.connect]))
    conf.insert_json5('scouting/multicast/enabled', 'false')
    session = zenoh.open(conf)
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
        after = ask(session, key, b'{}')
        out[key] = {'sent': AT_ONCE, 'answered': sum(a is not None for a in answers),
                    'refusals': [a['error'] for a in answers if a and not a['ok']],
                    'answered_after': after is not None}
    session.close()
    print(json.dumps(out))


if __name__ == '__main__':
    main()
