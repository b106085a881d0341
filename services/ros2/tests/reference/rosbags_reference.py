"""The reference values of services/ros2/tests/reference.rs, from PyPI's rosbags 0.11.9,
an implementation of ROS 2 messages independent of roam's:

    pip install rosbags==0.11.9 && python3 services/ros2/tests/reference/rosbags_reference.py

prints the CDR bytes of three messages and the RIHS01 hashes of roam's two services, of
Nav2's ComputePathToPose action (its services, built as rosidl builds them, and its
feedback message) and FollowPath, action_msgs's CancelGoal and GoalStatusArray, tf2's
TFMessage and rosgraph_msgs's Clock.
rosbags' own service_msgs/ServiceEventInfo reads `char[16]` as FIELD_TYPE_CHAR, which
disagrees with the AddTwoInts hash rmw_zenoh publishes; rosidl reads it as uint8, so the
services are hashed here in a type store that says uint8.
"""
import numpy as np
from rosbags.typesys import Stores, get_typestore, get_types_from_msg
ts = get_typestore(Stores.ROS2_JAZZY)
T = ts.types
Time=T['builtin_interfaces/msg/Time']; Header=T['std_msgs/msg/Header']
MMD=T['nav_msgs/msg/MapMetaData']; Pose=T['geometry_msgs/msg/Pose']; Point=T['geometry_msgs/msg/Point']; Q=T['geometry_msgs/msg/Quaternion']
OG=T['nav_msgs/msg/OccupancyGrid']; Path=T['nav_msgs/msg/Path']; PS=T['geometry_msgs/msg/PoseStamped']
PWCS=T['geometry_msgs/msg/PoseWithCovarianceStamped']; PWC=T['geometry_msgs/msg/PoseWithCovariance']
h=Header(stamp=Time(sec=1700000000,nanosec=5), frame_id='map')
og=OG(header=h, info=MMD(map_load_time=Time(sec=1,nanosec=2), resolution=np.float32(0.2), width=3, height=2,
  origin=Pose(position=Point(x=-10.0,y=-5.0,z=0.0), orientation=Q(x=0.0,y=0.0,z=0.0,w=1.0))), data=np.array([-1,0,100,50,0,0],dtype=np.int8))
print('OG', ts.serialize_cdr(og, OG.__msgtype__).hex())
p=Path(header=h, poses=[PS(header=h, pose=Pose(position=Point(x=1.5,y=-2.0,z=0.0), orientation=Q(x=0.0,y=0.0,z=0.0,w=1.0))),
  PS(header=h, pose=Pose(position=Point(x=2.0,y=-2.0,z=0.0), orientation=Q(x=0.0,y=0.0,z=0.5,w=0.75)))])
print('PATH', ts.serialize_cdr(p, Path.__msgtype__).hex())
cov=np.arange(36,dtype=np.float64)
pw=PWCS(header=h, pose=PWC(pose=Pose(position=Point(x=1.0,y=2.0,z=0.0), orientation=Q(x=0.0,y=0.0,z=0.0,w=1.0)), covariance=cov))
print('PWCS', ts.serialize_cdr(pw, PWCS.__msgtype__).hex())
# Service hashes via rosbags' generic RIHS01 over the service description built as messages.
srv = {}
srv.update(get_types_from_msg('''geometry_msgs/PoseStamped start
geometry_msgs/PoseStamped goal
float64 budget_s
string model
uint64 seed
float64 deadline_s''','roam_interfaces/srv/PlanDowntime_Request'))
srv.update(get_types_from_msg('''nav_msgs/Path path
float64 eta_s
float64 information
bool within_budget
bool reaches_goal
string error_code
string error_message''','roam_interfaces/srv/PlanDowntime_Response'))
srv.update(get_types_from_msg('''geometry_msgs/PoseStamped start
geometry_msgs/PoseStamped goal
float32 tolerance''','nav_msgs/srv/GetPlan_Request'))
srv.update(get_types_from_msg('nav_msgs/Path plan','nav_msgs/srv/GetPlan_Response'))
srv.update(get_types_from_msg('''uint8 event_type
builtin_interfaces/Time stamp
uint8[16] client_gid
int64 sequence_number''','service_msgs/msg/ServiceEventInfo'))
for s in ['roam_interfaces/srv/PlanDowntime','nav_msgs/srv/GetPlan']:
    srv.update(get_types_from_msg(f'''service_msgs/ServiceEventInfo info
{s}_Request[<=1] request
{s}_Response[<=1] response''', s+'_Event'))
    srv.update(get_types_from_msg(f'''{s}_Request request_message
{s}_Response response_message
{s}_Event event_message''', s))
base = get_typestore(Stores.ROS2_JAZZY)
ts = get_typestore(Stores.EMPTY)
need = ['builtin_interfaces/msg/Time','std_msgs/msg/Header','geometry_msgs/msg/Point','geometry_msgs/msg/Quaternion','geometry_msgs/msg/Pose','geometry_msgs/msg/PoseStamped','nav_msgs/msg/Path','nav_msgs/msg/OccupancyGrid','nav_msgs/msg/MapMetaData']
ts.register({k: base.fielddefs[k] for k in need})
def fix(o):
    if isinstance(o, str): return o.replace('/srv/msg/', '/srv/')
    if isinstance(o, tuple): return tuple(fix(x) for x in o)
    if isinstance(o, list): return [fix(x) for x in o]
    return o
srv = {fix(k): fix(v) for k, v in srv.items()}
ts.register(srv)
for s in ['roam_interfaces/srv/PlanDowntime','nav_msgs/srv/GetPlan']:
    print('HASH', s, ts.hash_rihs01(s))
print('HASH OG', ts.hash_rihs01('nav_msgs/msg/OccupancyGrid'))
# Nav2's planner action (its services built as rosidl builds them) and tf2's message.
P = 'nav2_msgs/action/ComputePathToPose'
act = {}
act.update(get_types_from_msg('geometry_msgs/PoseStamped goal\ngeometry_msgs/PoseStamped start\nstring planner_id\nbool use_start', P + '_Goal'))
act.update(get_types_from_msg('nav_msgs/Path path\nbuiltin_interfaces/Duration planning_time\nuint16 error_code\nstring error_msg', P + '_Result'))
act.update(get_types_from_msg('uint8 structure_needs_at_least_one_member', P + '_Feedback'))
act.update(get_types_from_msg(f'unique_identifier_msgs/UUID goal_id\n{P}_Feedback feedback', P + '_FeedbackMessage'))
F = 'nav2_msgs/action/FollowPath'
act.update(get_types_from_msg('nav_msgs/Path path\nstring controller_id\nstring goal_checker_id\nstring progress_checker_id', F + '_Goal'))
act.update(get_types_from_msg('std_msgs/Empty result\nuint16 error_code\nstring error_msg', F + '_Result'))
act.update(get_types_from_msg('float32 distance_to_goal\nfloat32 speed', F + '_Feedback'))
act.update(get_types_from_msg(f'unique_identifier_msgs/UUID goal_id\n{F}_Feedback feedback', F + '_FeedbackMessage'))
for s, req, resp in [
        (F + '_SendGoal', f'unique_identifier_msgs/UUID goal_id\n{F}_Goal goal', 'bool accepted\nbuiltin_interfaces/Time stamp'),
        (F + '_GetResult', 'unique_identifier_msgs/UUID goal_id', f'int8 status\n{F}_Result result'),
        (P + '_SendGoal', f'unique_identifier_msgs/UUID goal_id\n{P}_Goal goal', 'bool accepted\nbuiltin_interfaces/Time stamp'),
        (P + '_GetResult', 'unique_identifier_msgs/UUID goal_id', f'int8 status\n{P}_Result result'),
        ('action_msgs/srv/CancelGoal', 'action_msgs/GoalInfo goal_info', 'int8 return_code\naction_msgs/GoalInfo[] goals_canceling')]:
    act.update(get_types_from_msg(req, s + '_Request'))
    act.update(get_types_from_msg(resp, s + '_Response'))
    act.update(get_types_from_msg(f'service_msgs/ServiceEventInfo info\n{s}_Request[<=1] request\n{s}_Response[<=1] response', s + '_Event'))
    act.update(get_types_from_msg(f'{s}_Request request_message\n{s}_Response response_message\n{s}_Event event_message', s))
def fix_action(o):
    if isinstance(o, str): return fix(o).replace('/action/msg/', '/action/')
    if isinstance(o, tuple): return tuple(fix_action(x) for x in o)
    if isinstance(o, list): return [fix_action(x) for x in o]
    return o
ts.register({k: base.fielddefs[k] for k in ['builtin_interfaces/msg/Duration', 'unique_identifier_msgs/msg/UUID', 'action_msgs/msg/GoalInfo', 'action_msgs/msg/GoalStatus', 'action_msgs/msg/GoalStatusArray', 'geometry_msgs/msg/Vector3', 'geometry_msgs/msg/Transform', 'geometry_msgs/msg/TransformStamped', 'tf2_msgs/msg/TFMessage', 'rosgraph_msgs/msg/Clock', 'std_msgs/msg/Empty']})
ts.register({fix_action(k): fix_action(v) for k, v in act.items()})
for s in [P + '_SendGoal', P + '_GetResult', P + '_FeedbackMessage', 'action_msgs/srv/CancelGoal', 'action_msgs/msg/GoalStatusArray', 'tf2_msgs/msg/TFMessage', F + '_SendGoal', F + '_GetResult', F + '_FeedbackMessage', 'rosgraph_msgs/msg/Clock']:
    print('HASH', s, ts.hash_rihs01(s))
