"""A ROS 2 client of roam that shares no code with it: rmw_zenoh's wire built from its
spec with PyPI's `eclipse-zenoh` (1.10.2) and `rosbags` (0.11.9, an independent ROS 2
message implementation: CDR, RIHS01 hashes, rosbag2 reading).

    python3 ros2_client.py live --connect tcp/127.0.0.1:7447 --robot r1 --waypoints '[[..]]'
    python3 ros2_client.py watch --connect tcp/127.0.0.1:7447 --robot robot
    python3 ros2_client.py nav2 --connect tcp/127.0.0.1:7447 --robot r1
    python3 ros2_client.py graph --connect tcp/127.0.0.1:7447 --within 5
    python3 ros2_client.py fleet --connect tcp/127.0.0.1:7447 --robots r1,r2,r3
    python3 ros2_client.py fake-nav2-robot --connect tcp/127.0.0.1:7447 --speed 0.6 --rate 10
    python3 ros2_client.py bag DIR

`live` finds roam's liveliness tokens, subscribes to /map and /<robot>/plan as
rmw_zenoh's transient-local subscriber does (an AdvancedSubscriber asking the
publishers' caches), checks the attachments, calls /roam/plan_downtime and
/roam/get_plan with rmw_zenoh's query conventions (good and bad requests), and prints
one JSON object (the map's cells in hex, for the caller to compare with the map
server's layer). `watch` follows a robot that roam drives (the demo): /map, the
robot's /<robot>/plan and its /<robot>/pose with the CRB as covariance. `nav2` is a Nav2
client: it sends nav2_msgs/action/ComputePathToPose goals (good ones, and ones in a wall,
off the map, in another frame, to an unknown planner, cancelled) with rcl_action's
services on keys built from rosbags' hashes, checks Nav2's status and error codes, the
latched status topic, and /tf against the robot's estimates. `graph` waits for roam's node
and its action among the graph's tokens (after a router restart, say). `fleet` finds
every robot of a fleet on /tf and its pose topic. `fake-nav2-robot`
is a Nav2 robot (/clock, /amcl_pose, a FollowPath server driving the pose along each
path) for roam's executive to drive through the node. `bag` reads a
rosbag2 directory and prints its topics and counts.
Exit code 0 when every check passed; 1 with the failed check on stderr otherwise.
"""

import argparse
import json
import math
import os
import sys
import time

import numpy as np
import zenoh
import zenoh.ext
from rosbags.typesys import Stores, get_typestore, get_types_from_msg

STORE = get_typestore(Stores.ROS2_JAZZY)
SRV_DIR = os.path.join(os.path.dirname(__file__), '../../../services/ros2/roam_interfaces/srv')


def fail(what):
    print(f'FAILED: {what}', file=sys.stderr)
    sys.exit(1)


def check(cond, what):
    if not cond:
        fail(what)


def register_services():
    """PlanDowntime from the shipped .srv file, GetPlan from nav_msgs' definition."""
    text = open(os.path.join(SRV_DIR, 'PlanDowntime.srv')).read()
    request, response = text.split('\n---\n')
    types = {}
    types.update(get_types_from_msg(request, 'roam_interfaces/msg/PlanDowntime_Request'))
    types.update(get_types_from_msg(response, 'roam_interfaces/msg/PlanDowntime_Response'))
    types.update(get_types_from_msg(
        'geometry_msgs/PoseStamped start\ngeometry_msgs/PoseStamped goal\nfloat32 tolerance',
        'nav_msgs/msg/GetPlan_Request'))
    types.update(get_types_from_msg('nav_msgs/Path plan', 'nav_msgs/msg/GetPlan_Response'))
    STORE.register(types)


def dds(ros_type):
    pkg, kind, name = ros_type.split('/')
    return f'{pkg}::{kind}::dds_::{name}_'


def topic_key(domain, name, ros_type, digest):
    return f'{domain}/{name.strip("/")}/{dds(ros_type)}/{digest}'


def attachment(seq, gid):
    return seq.to_bytes(8, 'little', signed=True) + time.time_ns().to_bytes(8, 'little', signed=True) \
        + bytes([16]) + gid


def parse_attachment(raw):
    check(raw is not None, 'a sample or reply has rmw_zenoh\'s attachment')
    data = raw.to_bytes()
    check(len(data) == 33, f'the attachment is 33 bytes (got {len(data)})')
    check(data[16] == 16, 'the GID length byte is 16')
    seq = int.from_bytes(data[0:8], 'little', signed=True)
    stamp = int.from_bytes(data[8:16], 'little', signed=True)
    check(abs(stamp - time.time_ns()) < 600e9, 'the source timestamp is now, in ns since the epoch')
    return seq, data[17:]


def pose(x, y):
    T = STORE.types
    return T['geometry_msgs/msg/PoseStamped'](
        header=T['std_msgs/msg/Header'](stamp=T['builtin_interfaces/msg/Time'](sec=0, nanosec=0),
                                        frame_id='map'),
        pose=T['geometry_msgs/msg/Pose'](
            position=T['geometry_msgs/msg/Point'](x=x, y=y, z=0.0),
            orientation=T['geometry_msgs/msg/Quaternion'](x=0.0, y=0.0, z=0.0, w=1.0)))


def latest(session, key, timeout):
    """The last sample on `key`, as an rmw_zenoh transient-local subscription gets it:
    an AdvancedSubscriber that detects late publishers and queries their cache."""
    got = []
    sub = zenoh.ext.declare_advanced_subscriber(
        session, key, lambda s: got.append(s),
        history=zenoh.ext.HistoryConfig(detect_late_publishers=True, max_samples=1),
        subscriber_detection=True)
    deadline = time.time() + timeout
    while not got and time.time() < deadline:
        time.sleep(0.05)
    sub.undeclare()
    check(got, f'a sample on {key} within {timeout} s (transient local)')
    return got[-1]


class Caller:
    """A ROS 2 service client the rmw_zenoh way: get on the service key, target
    ALL_COMPLETE, no consolidation, the request's CDR as payload, the attachment with
    a sequence number from 1 and the client's GID."""

    def __init__(self, session, key, gid):
        self.session, self.key, self.gid, self.seq = session, key, gid, 0

    def call_raw(self, payload):
        self.seq += 1
        replies = self.session.get(
            self.key, payload=bytes(payload), attachment=attachment(self.seq, self.gid),
            target=zenoh.QueryTarget.ALL_COMPLETE,
            consolidation=zenoh.ConsolidationMode.NONE, timeout=60.0)
        for reply in replies:
            check(reply.ok is not None, f'{self.key} replied with an error: {reply.err}')
            seq, gid = parse_attachment(reply.ok.attachment)
            check(seq == self.seq, f'the reply echoes sequence number {self.seq} (got {seq})')
            check(gid == self.gid, 'the reply echoes the client GID')
            check(str(reply.ok.key_expr) == self.key, 'the reply is on the service key')
            return reply.ok.payload.to_bytes()
        fail(f'no reply on {self.key}')

    def call(self, msg, req_type, resp_type):
        data = self.call_raw(STORE.serialize_cdr(msg, req_type))
        return STORE.deserialize_cdr(data, resp_type)


STORM_CALLS = 1000
STORM_WITHIN_S = 60.0


def storm(session, key, gid, payload):
    """STORM_CALLS GetPlan calls sent at once, the rmw_zenoh way; waits up to
    STORM_WITHIN_S for their responses and counts them (and the empty paths)."""
    import threading
    cond = threading.Condition()
    seen = {'answered': 0, 'empty': 0, 'errors': 0}

    def on_reply(reply):
        with cond:
            if reply.ok is None:
                seen['errors'] += 1
            else:
                r = STORE.deserialize_cdr(reply.ok.payload.to_bytes(),
                                          'nav_msgs/msg/GetPlan_Response')
                seen['answered'] += 1
                seen['empty'] += len(r.plan.poses) == 0
            cond.notify_all()

    start = time.time()
    for seq in range(1, STORM_CALLS + 1):
        session.get(key, payload=payload, attachment=attachment(100000 + seq, gid),
                    target=zenoh.QueryTarget.ALL_COMPLETE,
                    consolidation=zenoh.ConsolidationMode.NONE, timeout=STORM_WITHIN_S,
                    handler=on_reply)
    with cond:
        cond.wait_for(lambda: seen['answered'] + seen['errors'] >= STORM_CALLS,
                      timeout=STORM_WITHIN_S)
        result = dict(seen, calls=STORM_CALLS, seconds=round(time.time() - start, 2))
    check(result['errors'] == 0, f'no get_plan call in the storm is an error: {result}')
    check(result['answered'] == STORM_CALLS, f'every get_plan call in the storm is answered: {result}')
    return result


def live(args):
    register_services()
    domain = args.domain
    session = open_client(args.connect)
    out = {}

    h_grid = STORE.hash_rihs01('nav_msgs/msg/OccupancyGrid')
    h_path = STORE.hash_rihs01('nav_msgs/msg/Path')
    map_key = topic_key(domain, '/map', 'nav_msgs/msg/OccupancyGrid', h_grid)
    plan_key = topic_key(domain, f'/{args.robot}/plan', 'nav_msgs/msg/Path', h_path)

    # The graph: roam's node and its endpoints, as rmw_zenoh's graph cache reads them.
    tokens = []
    deadline = time.time() + 30
    while time.time() < deadline:
        tokens = [str(r.ok.key_expr) for r in session.liveliness().get(f'@ros2_lv/{domain}/**')
                  if r.ok is not None]
        if any('/MP/' in t and '/%map/' in t for t in tokens) and any('/SS/' in t for t in tokens):
            break
        time.sleep(0.2)
    parts = [t.split('/') for t in tokens]
    nodes = [p for p in parts if len(p) == 9 and p[5] == 'NN' and p[8] == 'roam']
    check(nodes, f'a node token for /roam among {tokens}')
    check(nodes[0][6] == '%' and nodes[0][7] == '%', 'empty enclave and root namespace as %')
    zid = nodes[0][2]
    mine = [p for p in parts if p[2] == zid and len(p) == 13]
    want = {
        ('MP', '%map', dds('nav_msgs/msg/OccupancyGrid'), h_grid, ':1:,1:,:,:,,'),
        ('MP', f'%{args.robot}%plan', dds('nav_msgs/msg/Path'), h_path, ':1:,1:,:,:,,'),
        ('SS', '%roam%get_plan', 'nav_msgs::srv::dds_::GetPlan_', None, '::,10:,:,:,,'),
        ('SS', '%roam%plan_downtime', 'roam_interfaces::srv::dds_::PlanDowntime_', None, '::,10:,:,:,,'),
    }
    for kind, name, ty, digest, qos in want:
        found = [p for p in mine if p[5] == kind and p[9] == name and p[10] == ty and p[12] == qos
                 and (digest is None or p[11] == digest) and p[3] == nodes[0][3]]
        check(found, f'an endpoint token {kind} {name} {ty} {qos}')
    service_hash = {p[9]: p[11] for p in mine if p[5] == 'SS'}
    out['tokens'] = len(mine) + 1

    # /map, decoded by rosbags, its attachment checked.
    sample = latest(session, map_key, 30)
    seq, gid = parse_attachment(sample.attachment)
    check(seq >= 1, 'sequence numbers start at 1')
    raw = sample.payload.to_bytes()
    check(raw[:4] == b'\x00\x01\x00\x00', 'CDR little-endian encapsulation')
    grid = STORE.deserialize_cdr(raw, 'nav_msgs/msg/OccupancyGrid')
    check(grid.header.frame_id == 'map', 'the map is in frame map')
    out['map'] = {
        'width': int(grid.info.width), 'height': int(grid.info.height),
        'resolution': float(grid.info.resolution),
        'origin': [grid.info.origin.position.x, grid.info.origin.position.y],
        'data_hex': np.asarray(grid.data, dtype=np.int8).tobytes().hex(),
        'gid_hex': gid.hex(),
    }

    # /<robot>/plan.
    sample = latest(session, plan_key, 30)
    parse_attachment(sample.attachment)
    path = STORE.deserialize_cdr(sample.payload.to_bytes(), 'nav_msgs/msg/Path')
    got = [[p.pose.position.x, p.pose.position.y] for p in path.poses]
    check(got == json.loads(args.waypoints), f'/{args.robot}/plan holds the mission ({got})')
    out['plan_poses'] = len(got)

    gid = os.urandom(16)
    T = STORE.types
    Req = T['roam_interfaces/msg/PlanDowntime_Request']
    pd = Caller(session, topic_key(domain, '/roam/plan_downtime', 'roam_interfaces/srv/PlanDowntime',
                                   service_hash['%roam%plan_downtime']), gid)
    rt, st = 'roam_interfaces/msg/PlanDowntime_Request', 'roam_interfaces/msg/PlanDowntime_Response'
    good = Req(start=pose(-8.0, -8.0), goal=pose(6.0, -7.0), budget_s=80.0, model='model1', seed=7,
               deadline_s=3.0)
    r = pd.call(good, rt, st)
    check(r.error_code == '', f'plan_downtime succeeds ({r.error_code}: {r.error_message})')
    check(r.reaches_goal and r.within_budget and r.eta_s <= 80.0, 'the plan reaches the goal in budget')
    last = r.path.poses[-1].pose.position
    check(math.hypot(last.x - 6.0, last.y + 7.0) < 0.5, 'the path ends at the goal')
    out['plan_downtime'] = {'poses': len(r.path.poses), 'eta_s': r.eta_s, 'information': r.information}

    bad = {
        'nan': (Req(start=pose(float('nan'), -8.0), goal=pose(6.0, -7.0), budget_s=80.0, model='',
                    seed=0, deadline_s=0.0), 'invalid_request'),
        'short_budget': (Req(start=pose(-8.0, -8.0), goal=pose(6.0, -7.0), budget_s=1.0, model='',
                             seed=0, deadline_s=0.0), 'invalid_request'),
        'model': (Req(start=pose(-8.0, -8.0), goal=pose(6.0, -7.0), budget_s=80.0, model='model9',
                      seed=0, deadline_s=0.0), 'invalid_request'),
    }
    out['refusals'] = {}
    for name, (msg, code) in bad.items():
        r = pd.call(msg, rt, st)
        check(r.error_code == code and r.error_message, f'{name}: error {code} (got {r.error_code!r})')
        check(len(r.path.poses) == 0, f'{name}: an empty path')
        out['refusals'][name] = r.error_message
    truncated = bytes(STORE.serialize_cdr(good, rt))[:20]
    r = STORE.deserialize_cdr(pd.call_raw(truncated), st)
    check(r.error_code == 'malformed', f'a truncated request is malformed (got {r.error_code!r})')
    out['refusals']['truncated'] = r.error_message

    gp = Caller(session, topic_key(domain, '/roam/get_plan', 'nav_msgs/srv/GetPlan',
                                   service_hash['%roam%get_plan']), gid)
    GReq = T['nav_msgs/msg/GetPlan_Request']
    r = gp.call(GReq(start=pose(-8.0, -8.0), goal=pose(6.0, -7.0), tolerance=0.0),
                'nav_msgs/msg/GetPlan_Request', 'nav_msgs/msg/GetPlan_Response')
    check(len(r.plan.poses) > 1, 'get_plan returns a path')
    last = r.plan.poses[-1].pose.position
    check(math.hypot(last.x - 6.0, last.y + 7.0) < 0.5, 'the get_plan path ends at the goal')
    r = gp.call(GReq(start=pose(-8.0, -8.0), goal=pose(float('inf'), -7.0), tolerance=0.0),
                'nav_msgs/msg/GetPlan_Request', 'nav_msgs/msg/GetPlan_Response')
    check(len(r.plan.poses) == 0, 'a get_plan to an infinite goal is an empty path')
    out['get_plan_poses'] = True

    # A storm: every call gets a response (an empty path at worst), none hangs.
    request = bytes(STORE.serialize_cdr(GReq(start=pose(-8.0, -8.0), goal=pose(6.0, -7.0),
                                             tolerance=0.0), 'nav_msgs/msg/GetPlan_Request'))
    out['get_plan_storm'] = storm(session, gp.key, gid, request)
    session.close()
    print(json.dumps(out))


NAV2 = 'nav2_msgs/action/ComputePathToPose'
FOLLOW = 'nav2_msgs/action/FollowPath'
STATUS = {'unknown': 0, 'accepted': 1, 'executing': 2, 'canceling': 3, 'succeeded': 4,
          'canceled': 5, 'aborted': 6}
NAV2_ERRORS = {'NONE': 0, 'UNKNOWN': 200, 'INVALID_PLANNER': 201, 'TF_ERROR': 202,
               'START_OUTSIDE_MAP': 203, 'GOAL_OUTSIDE_MAP': 204, 'START_OCCUPIED': 205,
               'GOAL_OCCUPIED': 206, 'TIMEOUT': 207, 'NO_VALID_PATH': 208}


def action_store():
    """nav2_msgs/action/ComputePathToPose from Nav2 Jazzy's .action text, with the parts
    rosidl generates for an action (SendGoal and GetResult services, FeedbackMessage) and
    action_msgs/srv/CancelGoal, in a type store where services hash as rosidl hashes
    them (ServiceEventInfo's char[16] as uint8)."""
    base = get_typestore(Stores.ROS2_JAZZY)
    store = get_typestore(Stores.EMPTY)
    store.register({k: base.fielddefs[k] for k in [
        'builtin_interfaces/msg/Time', 'builtin_interfaces/msg/Duration', 'std_msgs/msg/Header',
        'geometry_msgs/msg/Point', 'geometry_msgs/msg/Quaternion', 'geometry_msgs/msg/Pose',
        'geometry_msgs/msg/PoseStamped', 'nav_msgs/msg/Path', 'unique_identifier_msgs/msg/UUID',
        'action_msgs/msg/GoalInfo', 'action_msgs/msg/GoalStatus', 'action_msgs/msg/GoalStatusArray',
        'geometry_msgs/msg/Vector3', 'geometry_msgs/msg/Transform',
        'geometry_msgs/msg/TransformStamped', 'tf2_msgs/msg/TFMessage', 'rosgraph_msgs/msg/Clock',
        'std_msgs/msg/Empty', 'geometry_msgs/msg/PoseWithCovariance',
        'geometry_msgs/msg/PoseWithCovarianceStamped']})
    types = {}
    types.update(get_types_from_msg(
        'uint8 event_type\nbuiltin_interfaces/Time stamp\nuint8[16] client_gid\nint64 sequence_number',
        'service_msgs/msg/ServiceEventInfo'))
    P = NAV2
    types.update(get_types_from_msg('geometry_msgs/PoseStamped goal\ngeometry_msgs/PoseStamped start\n'
                                    'string planner_id\nbool use_start', P + '_Goal'))
    types.update(get_types_from_msg('nav_msgs/Path path\nbuiltin_interfaces/Duration planning_time\n'
                                    'uint16 error_code\nstring error_msg', P + '_Result'))
    types.update(get_types_from_msg('uint8 structure_needs_at_least_one_member', P + '_Feedback'))
    types.update(get_types_from_msg(f'unique_identifier_msgs/UUID goal_id\n{P}_Feedback feedback',
                                    P + '_FeedbackMessage'))
    F = FOLLOW
    types.update(get_types_from_msg('nav_msgs/Path path\nstring controller_id\nstring goal_checker_id\n'
                                    'string progress_checker_id', F + '_Goal'))
    types.update(get_types_from_msg('std_msgs/Empty result\nuint16 error_code\nstring error_msg', F + '_Result'))
    types.update(get_types_from_msg('float32 distance_to_goal\nfloat32 speed', F + '_Feedback'))
    types.update(get_types_from_msg(f'unique_identifier_msgs/UUID goal_id\n{F}_Feedback feedback',
                                    F + '_FeedbackMessage'))
    for srv, req, resp in [
            (F + '_SendGoal', f'unique_identifier_msgs/UUID goal_id\n{F}_Goal goal',
             'bool accepted\nbuiltin_interfaces/Time stamp'),
            (F + '_GetResult', 'unique_identifier_msgs/UUID goal_id', f'int8 status\n{F}_Result result'),
            (P + '_SendGoal', f'unique_identifier_msgs/UUID goal_id\n{P}_Goal goal',
             'bool accepted\nbuiltin_interfaces/Time stamp'),
            (P + '_GetResult', 'unique_identifier_msgs/UUID goal_id', f'int8 status\n{P}_Result result'),
            ('action_msgs/srv/CancelGoal', 'action_msgs/GoalInfo goal_info',
             'int8 return_code\naction_msgs/GoalInfo[] goals_canceling')]:
        types.update(get_types_from_msg(req, srv + '_Request'))
        types.update(get_types_from_msg(resp, srv + '_Response'))
        types.update(get_types_from_msg(
            f'service_msgs/ServiceEventInfo info\n{srv}_Request[<=1] request\n{srv}_Response[<=1] response',
            srv + '_Event'))
        types.update(get_types_from_msg(
            f'{srv}_Request request_message\n{srv}_Response response_message\n{srv}_Event event_message', srv))

    def fix(o):
        if isinstance(o, str):
            return o.replace('/srv/msg/', '/srv/').replace('/action/msg/', '/action/')
        if isinstance(o, (tuple, list)):
            return type(o)(fix(x) for x in o)
        return o
    store.register({fix(k): fix(v) for k, v in types.items()})
    return store


def nav2(args):
    """Nav2's side: ComputePathToPose as a Nav2 client sends it (rcl_action's services
    and topics on rmw_zenoh's keys, every key built here from rosbags' hashes), and /tf."""
    A = action_store()
    T = A.types
    domain = args.domain
    session = open_client(args.connect)
    out = {}
    action = f'/{args.action}/_action'

    def key_of(name, ros_type, service=False):
        return topic_key(domain, name, ros_type, A.hash_rihs01(ros_type))

    # The graph: the action's services and topics, and /tf, on rmw_zenoh's tokens.
    want = {
        ('SS', f'%{args.action}%_action%send_goal', dds(NAV2 + '_SendGoal'),
         A.hash_rihs01(NAV2 + '_SendGoal'), '::,10:,:,:,,'),
        ('SS', f'%{args.action}%_action%get_result', dds(NAV2 + '_GetResult'),
         A.hash_rihs01(NAV2 + '_GetResult'), '::,10:,:,:,,'),
        ('SS', f'%{args.action}%_action%cancel_goal', 'action_msgs::srv::dds_::CancelGoal_',
         A.hash_rihs01('action_msgs/srv/CancelGoal'), '::,10:,:,:,,'),
        ('MP', f'%{args.action}%_action%status', 'action_msgs::msg::dds_::GoalStatusArray_',
         A.hash_rihs01('action_msgs/msg/GoalStatusArray'), ':1:,1:,:,:,,'),
        ('MP', f'%{args.action}%_action%feedback', dds(NAV2 + '_FeedbackMessage'),
         A.hash_rihs01(NAV2 + '_FeedbackMessage'), '::,10:,:,:,,'),
        ('MP', '%tf', 'tf2_msgs::msg::dds_::TFMessage_', A.hash_rihs01('tf2_msgs/msg/TFMessage'),
         '::,100:,:,:,,'),
    }
    deadline = time.time() + 60
    missing = want
    while time.time() < deadline:
        tokens = [str(r.ok.key_expr).split('/') for r in
                  session.liveliness().get(f'@ros2_lv/{domain}/**') if r.ok is not None]
        missing = {w for w in want if not any(
            len(p) == 13 and (p[5], p[9], p[10], p[11], p[12]) == w for p in tokens)}
        if not missing:
            break
        time.sleep(0.3)
    check(not missing, f'endpoint tokens for the action and /tf: missing {missing}')
    out['tokens'] = len(want)

    # /map: a cell of a wall, for a goal in one.
    grid = STORE.deserialize_cdr(latest(session, topic_key(
        domain, '/map', 'nav_msgs/msg/OccupancyGrid', STORE.hash_rihs01('nav_msgs/msg/OccupancyGrid')),
        30).payload.to_bytes(), 'nav_msgs/msg/OccupancyGrid')
    w, h, res = int(grid.info.width), int(grid.info.height), float(grid.info.resolution)
    data = np.asarray(grid.data, dtype=np.int8).reshape(h, w)
    walls = [(r, c) for r in range(2, h - 2) for c in range(2, w - 2) if (data[r - 1:r + 2, c - 1:c + 2] == 100).all()]
    check(walls, 'the map has a wall away from its edge')
    r, c = walls[len(walls) // 2]
    wall = (grid.info.origin.position.x + (c + 0.5) * res, grid.info.origin.position.y + (r + 0.5) * res)

    # The robot's estimate, for a goal from its current pose.
    pose_key = topic_key(domain, f'/{args.robot}/pose', 'geometry_msgs/msg/PoseWithCovarianceStamped',
                         STORE.hash_rihs01('geometry_msgs/msg/PoseWithCovarianceStamped'))
    estimate = STORE.deserialize_cdr(latest(session, pose_key, 30).payload.to_bytes(),
                                     'geometry_msgs/msg/PoseWithCovarianceStamped').pose.pose.position

    gid = os.urandom(16)
    send = Caller(session, key_of(action + '/send_goal', NAV2 + '_SendGoal'), gid)
    result = Caller(session, key_of(action + '/get_result', NAV2 + '_GetResult'), gid)
    cancel = Caller(session, key_of(action + '/cancel_goal', 'action_msgs/srv/CancelGoal'), gid)

    def stamped(x, y, frame='map'):
        return T['geometry_msgs/msg/PoseStamped'](
            header=T['std_msgs/msg/Header'](stamp=T['builtin_interfaces/msg/Time'](sec=0, nanosec=0),
                                            frame_id=frame),
            pose=T['geometry_msgs/msg/Pose'](
                position=T['geometry_msgs/msg/Point'](x=x, y=y, z=0.0),
                orientation=T['geometry_msgs/msg/Quaternion'](x=0.0, y=0.0, z=0.0, w=1.0)))

    def uuid(raw):
        return T['unique_identifier_msgs/msg/UUID'](uuid=np.frombuffer(raw, dtype=np.uint8).copy())

    def send_goal(goal_id, goal, start=(-8.0, -8.0), planner_id='', use_start=True, frame='map'):
        msg = T[NAV2 + '_SendGoal_Request'](goal_id=uuid(goal_id), goal=T[NAV2 + '_Goal'](
            goal=stamped(goal[0], goal[1], frame), start=stamped(start[0], start[1]),
            planner_id=planner_id, use_start=use_start))
        data = send.call_raw(A.serialize_cdr(msg, NAV2 + '_SendGoal_Request'))
        return A.deserialize_cdr(data, NAV2 + '_SendGoal_Response')

    def get_result(goal_id):
        data = result.call_raw(A.serialize_cdr(T[NAV2 + '_GetResult_Request'](goal_id=uuid(goal_id)),
                                               NAV2 + '_GetResult_Request'))
        return A.deserialize_cdr(data, NAV2 + '_GetResult_Response')

    def cancel_goal(goal_id):
        info = T['action_msgs/msg/GoalInfo'](goal_id=uuid(goal_id),
                                             stamp=T['builtin_interfaces/msg/Time'](sec=0, nanosec=0))
        data = cancel.call_raw(A.serialize_cdr(T['action_msgs/srv/CancelGoal_Request'](goal_info=info),
                                               'action_msgs/srv/CancelGoal_Request'))
        return A.deserialize_cdr(data, 'action_msgs/srv/CancelGoal_Response')

    def run(name, goal, **kw):
        goal_id = os.urandom(16)
        accepted = send_goal(goal_id, goal, **kw)
        check(accepted.accepted, f'{name}: the goal is accepted')
        r = get_result(goal_id)
        return goal_id, r

    goals = {}
    cases = [
        ('curious', (6.0, -7.0), {}, 'succeeded', 'NONE'),
        ('grid_based', (6.0, -7.0), {'planner_id': 'GridBased'}, 'succeeded', 'NONE'),
        ('from_the_robot', (6.0, -7.0), {'use_start': False}, 'succeeded', 'NONE'),
        ('in_a_wall', wall, {}, 'aborted', 'GOAL_OCCUPIED'),
        ('off_the_map', (500.0, 500.0), {}, 'aborted', 'GOAL_OUTSIDE_MAP'),
        ('start_off_the_map', (6.0, -7.0), {'start': (-500.0, 3.0)}, 'aborted', 'START_OUTSIDE_MAP'),
        ('nan', (float('nan'), -7.0), {}, 'aborted', 'GOAL_OUTSIDE_MAP'),
        ('other_frame', (6.0, -7.0), {'frame': 'odom'}, 'aborted', 'TF_ERROR'),
        ('unknown_planner', (6.0, -7.0), {'planner_id': 'navfn'}, 'aborted', 'INVALID_PLANNER'),
    ]
    for name, goal, kw, status, code in cases:
        goal_id, r = run(name, goal, **kw)
        got = (r.status, int(r.result.error_code))
        check(got == (STATUS[status], NAV2_ERRORS[code]),
              f'{name}: status {status} and error {code}, got {got}: {r.result.error_msg!r}')
        check(r.result.path.header.frame_id == 'map', f'{name}: the path is in frame map')
        if status == 'succeeded':
            poses = [(p.pose.position.x, p.pose.position.y) for p in r.result.path.poses]
            check(len(poses) >= 2, f'{name}: a path')
            check(math.hypot(poses[-1][0] - goal[0], poses[-1][1] - goal[1]) < 0.5,
                  f'{name}: the path ends at the goal')
            start = (estimate.x, estimate.y) if kw.get('use_start') is False else kw.get('start', (-8.0, -8.0))
            check(math.hypot(poses[0][0] - start[0], poses[0][1] - start[1]) < 0.5,
                  f'{name}: the path starts at {start}, got {poses[0]}')
            planning = r.result.planning_time.sec + r.result.planning_time.nanosec * 1e-9
            check(planning > 0.0, f'{name}: a planning time')
            goals[name] = {'poses': len(poses), 'planning_time_s': round(planning, 3)}
        else:
            check(len(r.result.path.poses) == 0 and r.result.error_msg, f'{name}: an empty path and why')
            goals[name] = {'error_code': code, 'error_msg': r.result.error_msg}
    out['goals'] = goals

    # Cancel: a curious plan cancelled as soon as it is accepted ends canceled, at once.
    goal_id = os.urandom(16)
    check(send_goal(goal_id, (6.0, 8.0), planner_id='model2').accepted, 'the goal to cancel is accepted')
    started = time.time()
    c = cancel_goal(goal_id)
    check(c.return_code == 0 and len(c.goals_canceling) == 1
          and bytes(c.goals_canceling[0].goal_id.uuid) == goal_id,
          f'the cancel names the goal (return code {c.return_code})')
    r = get_result(goal_id)
    check(r.status == STATUS['canceled'], f'a cancelled goal ends canceled (status {r.status})')
    out['cancel'] = {'seconds': round(time.time() - started, 3)}
    c = cancel_goal(goal_id)
    check(c.return_code == 3, f'cancelling it again: GOAL_TERMINATED (got {c.return_code})')
    c = cancel_goal(os.urandom(16))
    check(c.return_code == 2, f'cancelling an unknown goal: UNKNOWN_GOAL_ID (got {c.return_code})')
    check(get_result(os.urandom(16)).status == STATUS['unknown'], 'the result of an unknown goal: UNKNOWN')

    # The latched status: every goal above with its final state.
    status = A.deserialize_cdr(latest(session, key_of(action + '/status', 'action_msgs/msg/GoalStatusArray'),
                                      10).payload.to_bytes(), 'action_msgs/msg/GoalStatusArray')
    states = {bytes(s.goal_info.goal_id.uuid): s.status for s in status.status_list}
    check(states.get(goal_id) == STATUS['canceled'], 'the status topic has the cancelled goal')
    check(len(states) >= len(cases) + 1, f'the status topic has every goal ({len(states)})')
    out['status_goals'] = len(states)

    # /tf: map → <robot>/base_link at the robot's estimate.
    tfs, poses = [], []
    sub_tf = session.declare_subscriber(key_of('/tf', 'tf2_msgs/msg/TFMessage'),
                                        lambda s: tfs.append(s.payload.to_bytes()))
    sub_pose = session.declare_subscriber(pose_key, lambda s: poses.append(s.payload.to_bytes()))
    deadline = time.time() + 20
    while (len(tfs) < 5 or len(poses) < 5) and time.time() < deadline:
        time.sleep(0.1)
    sub_tf.undeclare()
    sub_pose.undeclare()
    check(tfs and poses, f'/tf and /{args.robot}/pose samples ({len(tfs)}, {len(poses)})')
    transforms = [t for raw in tfs for t in A.deserialize_cdr(raw, 'tf2_msgs/msg/TFMessage').transforms]
    mine = [t for t in transforms if t.child_frame_id == f'{args.robot}/base_link']
    check(mine and all(t.header.frame_id == 'map' for t in mine),
          f'/tf has map -> {args.robot}/base_link ({[t.child_frame_id for t in transforms][:5]})')
    at = {(t.transform.translation.x, t.transform.translation.y) for t in mine}
    estimates = [STORE.deserialize_cdr(raw, 'geometry_msgs/msg/PoseWithCovarianceStamped').pose.pose.position
                 for raw in poses]
    matched = sum((e.x, e.y) in at for e in estimates)
    check(matched >= len(estimates) // 2, f'the frames are at the estimates ({matched} of {len(estimates)})')
    out['tf'] = {'transforms': len(mine), 'estimates': len(estimates), 'matched': matched}
    session.close()
    print(json.dumps(out))


def fake_nav2_robot(args):
    """A Nav2 robot as a ROS 2 system shows one to roam, on rmw_zenoh's wire: /clock
    (simulated time at --rate times wall time), /amcl_pose (the robot's pose with a
    covariance) and a /follow_path action server (nav2_msgs/action/FollowPath) that
    drives the pose along each accepted path at --speed m/s of simulated time, with
    feedback, from the pose's nearest path point on (searched forward, as Nav2's
    controllers prune a plan); a new goal replaces the running one, a cancel stops it. --reject refuses
    every goal, --silent never answers, --stop-pose-at S stops publishing poses from
    simulated time S. Runs until simulated time --until-s, then prints what it did."""
    import threading
    A = action_store()
    T = A.types
    domain = args.domain
    session = open_client(args.connect)
    key_of = lambda name, ros_type: topic_key(domain, name, ros_type, A.hash_rihs01(ros_type))
    gid = os.urandom(16)
    lock = threading.Lock()
    state = {'pos': list(args.start), 'path': [], 'goal': None, 'results': {}, 'waiting': {},
             'goals': 0, 'cancels': 0, 'rejected': 0, 'driven_m': 0.0, 'succeeded': 0}
    seq = {'n': 0}

    def att():
        seq['n'] += 1
        return attachment(seq['n'], gid)

    def reply(query, payload):
        raw = query.attachment.to_bytes() if query.attachment is not None else None
        check(raw is not None and len(raw) == 33, 'roam\'s call carries rmw_zenoh\'s attachment')
        back = raw[0:8] + time.time_ns().to_bytes(8, 'little', signed=True) + raw[16:33]
        query.reply(query.key_expr, bytes(payload), attachment=back)

    def result_bytes(status):
        R = T[FOLLOW + '_GetResult_Response'](status=status, result=T[FOLLOW + '_Result'](
            result=T['std_msgs/msg/Empty'](structure_needs_at_least_one_member=0),
            error_code=0 if status == STATUS['succeeded'] else 100, error_msg=''))
        return A.serialize_cdr(R, FOLLOW + '_GetResult_Response')

    def end(goal_id, status):
        """Under the lock: goal_id ends with status; its waiting get_result calls are answered."""
        state['results'][goal_id] = status
        for q in state['waiting'].pop(goal_id, []):
            reply(q, result_bytes(status))

    def on_send_goal(query):
        req = A.deserialize_cdr(query.payload.to_bytes(), FOLLOW + '_SendGoal_Request')
        goal_id = bytes(req.goal_id.uuid)
        if args.silent:
            return
        with lock:
            state['goals'] += 1
            accepted = not args.reject
            if accepted:
                if state['goal'] is not None:
                    end(state['goal'], STATUS['canceled'])
                state['goal'] = goal_id
                path = [(p.pose.position.x, p.pose.position.y) for p in req.goal.path.poses]
                # As Nav2's controllers prune the global plan: followed from the robot's
                # nearest path point, searched forward from the start to the first local
                # minimum of the distance (never a later pass of a loop), so never back
                # to a start the robot has passed.
                pos = state['pos']
                dist = lambda i: math.hypot(path[i][0] - pos[0], path[i][1] - pos[1])
                nearest = 0
                while nearest + 1 < len(path) and dist(nearest + 1) <= dist(nearest):
                    nearest += 1
                state['path'] = path[nearest:]
            else:
                state['rejected'] += 1
        resp = T[FOLLOW + '_SendGoal_Response'](accepted=accepted, stamp=T['builtin_interfaces/msg/Time'](sec=0, nanosec=0))
        reply(query, A.serialize_cdr(resp, FOLLOW + '_SendGoal_Response'))

    def on_get_result(query):
        req = A.deserialize_cdr(query.payload.to_bytes(), FOLLOW + '_GetResult_Request')
        goal_id = bytes(req.goal_id.uuid)
        with lock:
            if goal_id in state['results']:
                reply(query, result_bytes(state['results'][goal_id]))
            elif goal_id == state['goal']:
                state['waiting'].setdefault(goal_id, []).append(query)
            else:
                reply(query, result_bytes(STATUS['unknown']))

    def on_cancel(query):
        req = A.deserialize_cdr(query.payload.to_bytes(), 'action_msgs/srv/CancelGoal_Request')
        goal_id = bytes(req.goal_info.goal_id.uuid)
        with lock:
            canceling = []
            if goal_id == state['goal']:
                state['cancels'] += 1
                canceling = [req.goal_info]
                end(goal_id, STATUS['canceled'])
                state['goal'], state['path'] = None, []
            code = 0 if canceling else 2
        resp = T['action_msgs/srv/CancelGoal_Response'](return_code=code, goals_canceling=canceling)
        reply(query, A.serialize_cdr(resp, 'action_msgs/srv/CancelGoal_Response'))

    base = f'/{args.action}/_action'
    queryables = [
        session.declare_queryable(key_of(base + '/send_goal', FOLLOW + '_SendGoal'), on_send_goal, complete=True),
        session.declare_queryable(key_of(base + '/get_result', FOLLOW + '_GetResult'), on_get_result, complete=True),
        session.declare_queryable(key_of(base + '/cancel_goal', 'action_msgs/srv/CancelGoal'), on_cancel, complete=True),
    ]
    clock_pub = session.declare_publisher(key_of('/clock', 'rosgraph_msgs/msg/Clock'))
    pose_pub = session.declare_publisher(key_of('/amcl_pose', 'geometry_msgs/msg/PoseWithCovarianceStamped'))
    feedback_pub = session.declare_publisher(key_of(base + '/feedback', FOLLOW + '_FeedbackMessage'))
    Time = T['builtin_interfaces/msg/Time']

    def stamp(sim):
        return Time(sec=int(sim), nanosec=int((sim % 1) * 1e9))

    period = 0.02
    sim = 0.0
    started = time.time()
    cov = np.zeros(36)
    cov[0] = cov[7] = 0.01
    cov[35] = 0.05
    while sim < args.until_s:
        time.sleep(period)
        before, sim = sim, (time.time() - started) * args.rate
        step = args.speed * (sim - before)
        with lock:
            path, pos = state['path'], state['pos']
            while step > 0 and path:
                tx, ty = path[0]
                d = math.hypot(tx - pos[0], ty - pos[1])
                if d <= step:
                    pos[0], pos[1] = tx, ty
                    state['driven_m'] += d
                    step -= d
                    path.pop(0)
                else:
                    pos[0] += (tx - pos[0]) * step / d
                    pos[1] += (ty - pos[1]) * step / d
                    state['driven_m'] += step
                    step = 0
            goal = state['goal']
            if goal is not None and not path:
                end(goal, STATUS['succeeded'])
                state['succeeded'] += 1
                state['goal'] = None
            elif goal is not None:
                left = sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip([tuple(pos)] + path, path))
                fb = T[FOLLOW + '_FeedbackMessage'](
                    goal_id=T['unique_identifier_msgs/msg/UUID'](uuid=np.frombuffer(goal, dtype=np.uint8).copy()),
                    feedback=T[FOLLOW + '_Feedback'](distance_to_goal=np.float32(left), speed=np.float32(args.speed)))
                feedback_pub.put(bytes(A.serialize_cdr(fb, FOLLOW + '_FeedbackMessage')), attachment=att())
            x, y = pos
        clock_pub.put(bytes(A.serialize_cdr(T['rosgraph_msgs/msg/Clock'](clock=stamp(sim)), 'rosgraph_msgs/msg/Clock')),
                      attachment=att())
        if args.stop_pose_at is None or sim < args.stop_pose_at:
            msg = T['geometry_msgs/msg/PoseWithCovarianceStamped'](
                header=T['std_msgs/msg/Header'](stamp=stamp(sim), frame_id='map'),
                pose=T['geometry_msgs/msg/PoseWithCovariance'](
                    pose=T['geometry_msgs/msg/Pose'](
                        position=T['geometry_msgs/msg/Point'](x=x, y=y, z=0.0),
                        orientation=T['geometry_msgs/msg/Quaternion'](x=0.0, y=0.0, z=0.0, w=1.0)),
                    covariance=cov))
            pose_pub.put(bytes(A.serialize_cdr(msg, 'geometry_msgs/msg/PoseWithCovarianceStamped')),
                         attachment=att())
    for q in queryables:
        q.undeclare()
    with lock:
        out = {k: state[k] for k in ['goals', 'cancels', 'rejected', 'succeeded']}
        out['driven_m'] = round(state['driven_m'], 2)
        out['at'] = [round(v, 3) for v in state['pos']]
    session.close()
    print(json.dumps(out))


def fleet(args):
    """Every robot of a fleet as a ROS 2 user sees it: its frame on /tf (map ->
    <robot>/base_link) and its /<robot>/pose, for each robot named by --robots."""
    A = action_store()
    session = open_client(args.connect)
    robots = args.robots.split(',')
    frames, poses = set(), set()
    tf_key = topic_key(args.domain, '/tf', 'tf2_msgs/msg/TFMessage', A.hash_rihs01('tf2_msgs/msg/TFMessage'))

    def on_tf(sample):
        for t in A.deserialize_cdr(sample.payload.to_bytes(), 'tf2_msgs/msg/TFMessage').transforms:
            if t.header.frame_id == 'map':
                frames.add(t.child_frame_id)

    subs = [session.declare_subscriber(tf_key, on_tf)]
    h_pose = STORE.hash_rihs01('geometry_msgs/msg/PoseWithCovarianceStamped')
    for robot in robots:
        key = topic_key(args.domain, f'/{robot}/pose', 'geometry_msgs/msg/PoseWithCovarianceStamped', h_pose)
        subs.append(session.declare_subscriber(key, lambda s, r=robot: poses.add(r)))
    want = {f'{r}/base_link' for r in robots}
    deadline = time.time() + args.within
    while time.time() < deadline and not (want <= frames and set(robots) <= poses):
        time.sleep(0.1)
    for sub in subs:
        sub.undeclare()
    session.close()
    check(want <= frames, f'/tf has every robot\'s frame: missing {sorted(want - frames)}')
    check(set(robots) <= poses, f'every robot\'s pose: missing {sorted(set(robots) - poses)}')
    print(json.dumps({'frames': sorted(frames), 'poses': sorted(poses)}))


def graph(args):
    """Waits for roam's node and its action's send_goal service among the graph's tokens,
    as rmw_zenoh's graph cache learns them (a liveliness get on the domain), and prints
    how long that took; fails after --within seconds."""
    started = time.time()
    session = open_client(args.connect)
    seen = None
    while time.time() - started < args.within:
        tokens = [str(r.ok.key_expr) for r in session.liveliness().get(f'@ros2_lv/{args.domain}/**')
                  if r.ok is not None]
        node = any(t.endswith('/NN/%/%/roam') for t in tokens)
        action = any('/SS/' in t and '%compute_path_to_pose%_action%send_goal' in t for t in tokens)
        if node and action:
            seen = time.time() - started
            break
        time.sleep(0.1)
    session.close()
    check(seen is not None, f'roam\'s node and its action in the graph within {args.within} s')
    print(json.dumps({'seen_after_s': round(seen, 2)}))


def open_client(endpoint):
    conf = zenoh.Config()
    conf.insert_json5('mode', '"client"')
    conf.insert_json5('connect/endpoints', json.dumps([endpoint]))
    conf.insert_json5('scouting/multicast/enabled', 'false')
    return zenoh.open(conf)


def watch(args):
    session = open_client(args.connect)
    domain = args.domain
    h_grid = STORE.hash_rihs01('nav_msgs/msg/OccupancyGrid')
    h_path = STORE.hash_rihs01('nav_msgs/msg/Path')
    h_pose = STORE.hash_rihs01('geometry_msgs/msg/PoseWithCovarianceStamped')
    out = {}
    sample = latest(session, topic_key(domain, '/map', 'nav_msgs/msg/OccupancyGrid', h_grid), 60)
    grid = STORE.deserialize_cdr(sample.payload.to_bytes(), 'nav_msgs/msg/OccupancyGrid')
    out['map'] = {'width': int(grid.info.width), 'height': int(grid.info.height),
                  'resolution': float(grid.info.resolution)}
    sample = latest(session, topic_key(domain, f'/{args.robot}/plan', 'nav_msgs/msg/Path', h_path), 60)
    path = STORE.deserialize_cdr(sample.payload.to_bytes(), 'nav_msgs/msg/Path')
    out['plan'] = [[p.pose.position.x, p.pose.position.y] for p in path.poses]
    check(len(out['plan']) >= 2, f'/{args.robot}/plan holds a path')
    pose_key = topic_key(domain, f'/{args.robot}/pose',
                         'geometry_msgs/msg/PoseWithCovarianceStamped', h_pose)
    sample = latest(session, pose_key, 60)
    parse_attachment(sample.attachment)
    pose = STORE.deserialize_cdr(sample.payload.to_bytes(),
                                 'geometry_msgs/msg/PoseWithCovarianceStamped')
    cov = [float(c) for c in pose.pose.covariance]
    check(pose.header.frame_id == 'map', 'the pose is in frame map')
    check(len(cov) == 36 and cov[0] > 0 and cov[7] > 0 and all(math.isfinite(c) for c in cov),
          f'the pose carries a covariance (the CRB): {cov[:8]}')
    out['pose'] = {'x': pose.pose.pose.position.x, 'y': pose.pose.pose.position.y,
                   'var_x': cov[0], 'var_y': cov[7]}
    session.close()
    print(json.dumps(out))


def bag(args):
    from rosbags.rosbag2 import Reader
    out = {'topics': {}}
    with Reader(args.dir) as reader:
        check(reader.message_count > 0, 'the bag holds messages')
        for conn in reader.connections:
            out['topics'][conn.topic] = {'type': conn.msgtype, 'count': conn.msgcount,
                                         'hash': conn.digest}
        for conn, stamp, raw in reader.messages():
            if conn.topic == '/map':
                grid = STORE.deserialize_cdr(raw, conn.msgtype)
                out['map'] = {'width': int(grid.info.width), 'height': int(grid.info.height)}
            elif conn.msgtype == 'nav_msgs/msg/Path':
                STORE.deserialize_cdr(raw, conn.msgtype)
    check('map' in out, 'the bag holds /map')
    print(json.dumps(out))


def main():
    parser = argparse.ArgumentParser()
    sub = parser.add_subparsers(dest='command', required=True)
    p = sub.add_parser('live')
    p.add_argument('--connect', required=True)
    p.add_argument('--domain', type=int, default=0)
    p.add_argument('--robot', default='r1')
    p.add_argument('--waypoints', required=True)
    p = sub.add_parser('watch')
    p.add_argument('--connect', required=True)
    p.add_argument('--domain', type=int, default=0)
    p.add_argument('--robot', default='robot')
    p = sub.add_parser('nav2')
    p.add_argument('--connect', required=True)
    p.add_argument('--domain', type=int, default=0)
    p.add_argument('--robot', default='r1')
    p.add_argument('--action', default='compute_path_to_pose')
    p = sub.add_parser('graph')
    p.add_argument('--connect', required=True)
    p.add_argument('--domain', type=int, default=0)
    p.add_argument('--within', type=float, default=5.0)
    p = sub.add_parser('fleet')
    p.add_argument('--connect', required=True)
    p.add_argument('--domain', type=int, default=0)
    p.add_argument('--robots', required=True)
    p.add_argument('--within', type=float, default=60.0)
    p = sub.add_parser('fake-nav2-robot')
    p.add_argument('--connect', required=True)
    p.add_argument('--domain', type=int, default=0)
    p.add_argument('--action', default='follow_path')
    p.add_argument('--start', type=float, nargs=2, default=[-8.0, -8.0])
    p.add_argument('--speed', type=float, default=0.6)
    p.add_argument('--rate', type=float, default=10.0)
    p.add_argument('--until-s', type=float, default=360.0)
    p.add_argument('--reject', action='store_true')
    p.add_argument('--silent', action='store_true')
    p.add_argument('--stop-pose-at', type=float, default=None)
    p = sub.add_parser('bag')
    p.add_argument('dir')
    args = parser.parse_args()
    {'live': live, 'watch': watch, 'nav2': nav2, 'graph': graph, 'fleet': fleet,
     'fake-nav2-robot': fake_nav2_robot,
     'bag': bag}[args.command](args)


if __name__ == '__main__':
    main()
