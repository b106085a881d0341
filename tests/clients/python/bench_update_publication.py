#!/usr/bin/env python3
"""What a one-cell update costs a running map server in publication (eclipse-zenoh only).

Creates a 4096 x 4096 f32 layer ("bench") on the map server behind --connect, follows
every publication under <root>/map/**, then sends UPDATES one-cell `set_cells` updates to
it, each on another cell. For each update it waits for the ack and for what the map
server publishes for it (the whole layer on <root>/map/layer/bench, or a delta on
<root>/map/delta/bench), and reads the map server's CPU time (utime + stime of --pid,
from /proc). Prints one JSON object: bytes published per update and the map server's
CPU seconds per update (median and max).

    python3 bench_update_publication.py --connect tcp/127.0.0.1:7447 --pid PID [--updates 10]
"""
import argparse
import base64
import json
import os
import statistics
import threading
import time

import zenoh

SIDE = 4096
TIMEOUT_S = 120.0


def open_session(endpoint):
    conf = zenoh.Config()
    conf.insert_json5('mode', '"client"')
    conf.insert_json5('connect/endpoints', json.dumps([endpoint]))
    conf.insert_json5('scouting/multicast/enabled', 'false')
    return zenoh.open(conf)


def cpu_s(pid):
    with open(f'/proc/{pid}/stat') as f:
        fields = f.read().rsplit(')', 1)[1].split()
    ticks = os.sysconf('SC_CLK_TCK')
    return (int(fields[11]) + int(fields[12])) / ticks


def message(kind, body):
    return json.dumps({'v': 1, 'kind': kind, 'body': body}).encode()


def ask(session, key, payload):
    for reply in session.get(key, payload=payload, timeout=TIMEOUT_S):
        if reply.ok is not None:
            return json.loads(reply.ok.payload.to_bytes())['body']
        raise RuntimeError(reply.err.payload.to_string()[:300])
    raise RuntimeError(f'no reply from {key}')


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument('--connect', required=True)
    parser.add_argument('--pid', type=int, required=True)
    parser.add_argument('--root', default='roam')
    parser.add_argument('--updates', type=int, default=10)
    args = parser.parse_args()
    session = open_session(args.connect)
    received = []
    arrived = threading.Condition()

    def on_sample(sample):
        with arrived:
            received.append((str(sample.key_expr), len(sample.payload.to_bytes())))
            arrived.notify_all()

    subscriber = session.declare_subscriber(f'{args.root}/map/**', on_sample)
    time.sleep(1.0)

    cells = base64.b64encode(bytes(SIDE * SIDE * 4)).decode()  # f32 zeros
    meta = {'width': SIDE, 'height': SIDE, 'resolution': 0.05,
            'origin': {'x': 0.0, 'y': 0.0, 'yaw': 0.0}}
    update_key = f'{args.root}/map/update/bench'
    ask(session, update_key, message('layer_update', {
        'base_version': 0,
        'change': {'op': 'replace', 'meta': meta, 'cells': {'dtype': 'f32', 'base64': cells}},
    }))
    del cells
    deadline = time.monotonic() + TIMEOUT_S
    with arrived:
        while not received and time.monotonic() < deadline:
            arrived.wait(1.0)
    time.sleep(2.0)

    per_update = []
    for i in range(args.updates):
        with arrived:
            received.clear()
        before = cpu_s(args.pid)
        ack = ask(session, update_key, message('layer_update', {
            'base_version': i + 1,
            'change': {'op': 'set_cells', 'cells': [{'x': i, 'y': 7, 'value': 0.5}]},
        }))
        assert ack['version'] == i + 2, ack
        deadline = time.monotonic() + TIMEOUT_S
        with arrived:
            while not received and time.monotonic() < deadline:
                arrived.wait(0.5)
        # Anything else the update publishes, and the map server's work on it.
        time.sleep(1.0)
        after = cpu_s(args.pid)
        with arrived:
            got = list(received)
        per_update.append({'cpu_s': after - before, 'bytes': sum(b for _, b in got),
                           'keys': sorted({k for k, _ in got})})
    subscriber.undeclare()
    session.close()
    cpu = [u['cpu_s'] for u in per_update]
    sizes = [u['bytes'] for u in per_update]
    print(json.dumps({
        'side': SIDE, 'dtype': 'f32', 'updates': args.updates,
        'bytes_published': {'median': statistics.median(sizes), 'max': max(sizes)},
        'cpu_s': {'median': round(statistics.median(cpu), 3), 'max': round(max(cpu), 3)},
        'keys': per_update[0]['keys'],
    }))


if __name__ == '__main__':
    main()
