#!/usr/bin/env bash
# Makes the secrets and the router config of a secure roam site with the openssl CLI:
#
#   ca.crt, ca.key           a site CA (10 years)
#   router.crt, router.key   the router's TLS certificate, signed by the CA (825 days), with
#                            the given names as subject alternative names
#   users.txt                Zenoh's user/password dictionary: one `user:password` line per
#                            user, random passwords
#   <user>.json5             one Zenoh client config per user (deploy/secure/client.json5
#                            with that user, its password, the CA path and router endpoint)
#   router.json5             the router's config: deploy/secure/router.json5 with each
#                            robot's rules, subjects and policies, the install dir's paths
#                            and the ROS domain
#
# The users: one per role that serves the whole fleet (map-server planner localization
# mapper sim operator, ros2 for the ROS 2 node, ros-node for other ROS 2 nodes), and two
# per robot: mission-<id> (its executive) and controller-<id> (its controller), whose rules
# reach that robot's keys only.
#
# Usage: deploy/secure/make-secrets.sh [--robots ID,ID,...] [--out DIR] [--install-dir DIR]
#                                      [--connect ENDPOINT] [--ros-domain N] [--force]
#                                      [NAME ...]
#
#   NAME           a DNS name or an IP address of the router (default: router localhost
#                  127.0.0.1); clients must connect with one of them
#   --robots       the fleet's robots (roam names: 1 to 64 of a-z A-Z 0-9 _ -), comma-
#                  separated or repeated; default: the robots of the last run in --out
#   --out          where to write (default: deploy/secure/secrets/, git-ignored)
#   --install-dir  where the files will live on the machines, written into the configs
#                  (default: /etc/roam/secrets)
#   --connect      the router endpoint in the client configs (default: tls/<first NAME>:7447)
#   --ros-domain   the ROS_DOMAIN_ID of the ROS 2 rules (default: 0)
#   --force        make everything anew (new CA, new passwords)
#
# Run again, it keeps the CA, the keys and the passwords it finds and only makes what is
# missing (a router certificate is remade when its names change, a robot added gets its
# users); the client configs and router.json5 are remade when they differ, and the users
# of a robot no longer in the fleet are removed with their configs. Everything is
# written readable by the owner only.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
out="$here/secrets"
install_dir="/etc/roam/secrets"
connect=""
ros_domain=0
force=0
names=()
robots=()
robots_given=0

die() { echo "make-secrets.sh: $*" >&2; exit 2; }

while [[ $# -gt 0 ]]; do
  case "$1" in
    --robots)
      [[ -n "${2:-}" ]] || die "--robots needs robot names, e.g. --robots r1,r2,r3"
      IFS=, read -r -a listed <<<"$2"
      robots+=("${listed[@]}")
      robots_given=1
      shift 2 ;;
    --out) out="${2:?--out needs a directory}"; shift 2 ;;
    --install-dir) install_dir="${2:?--install-dir needs a directory}"; shift 2 ;;
    --connect) connect="${2:?--connect needs an endpoint, e.g. tls/router:7447}"; shift 2 ;;
    --ros-domain) ros_domain="${2:?--ros-domain needs a number, 0 to 232}"; shift 2 ;;
    --force) force=1; shift ;;
    -h|--help) sed -n '2,39p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) die "unknown option $1 (see --help)" ;;
    *) names+=("$1"); shift ;;
  esac
done
[[ ${#names[@]} -gt 0 ]] || names=(router localhost 127.0.0.1)
[[ -n "$connect" ]] || connect="tls/${names[0]}:7447"
[[ "$ros_domain" =~ ^[0-9]{1,3}$ && "$ros_domain" -le 232 ]] ||
  die "--ros-domain $ros_domain: a ROS_DOMAIN_ID is 0 to 232"

# The roles that serve the whole fleet, one user each (router.json5's subjects).
fleet_users=(map-server planner localization mapper sim operator ros2 ros-node)

command -v openssl >/dev/null || { echo "make-secrets.sh: needs the openssl CLI" >&2; exit 1; }
template="$here/router.json5"
client_template="$here/client.json5"
for file in "$template" "$client_template"; do
  [[ -f "$file" ]] || { echo "make-secrets.sh: missing $file" >&2; exit 1; }
done
umask 077
mkdir -p "$out"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

wrote() { echo "  wrote $1"; }
kept() { echo "  kept  $1"; }
# Puts $tmp/$1 at $out/$1 unless the same file is there already.
install_file() {
  if cmp -s "$tmp/$1" "$out/$1" 2>/dev/null; then
    kept "$out/$1${2:+ ($2)}"
  else
    cp "$tmp/$1" "$out/$1"
    wrote "$out/$1${2:+ ($2)}"
  fi
}

# Users of the last run: their passwords are kept (unless --force), and their configs
# are this script's to remove when they leave.
declare -A password=()
old_users=()
if [[ -f "$out/users.txt" ]]; then
  while IFS=: read -r user pass; do
    [[ -n "$user" && -n "$pass" ]] || continue
    old_users+=("$user")
    [[ $force -eq 1 ]] || password["$user"]="$pass"
  done <"$out/users.txt"
fi

# The fleet: --robots, or the last run's.
if [[ $robots_given -eq 0 && $force -eq 0 && -f "$out/robots" ]]; then
  mapfile -t robots <"$out/robots"
fi
declare -A seen=()
for robot in "${robots[@]}"; do
  [[ "$robot" =~ ^[A-Za-z0-9_-]{1,64}$ ]] ||
    die "robot '$robot' is not a roam robot name: use 1 to 64 characters from a-z, A-Z, 0-9, '_' and '-'"
  [[ -z "${seen[$robot]:-}" ]] || die "robot '$robot' is named twice"
  seen["$robot"]=1
done
[[ ${#robots[@]} -gt 0 ]] ||
  echo "make-secrets.sh: no robots (--robots r1,r2,...): no executive or controller can log in" >&2
users=("${fleet_users[@]}")
for robot in "${robots[@]}"; do users+=("mission-$robot" "controller-$robot"); done

if [[ $force -eq 1 ]]; then
  rm -f "$out"/ca.crt "$out"/ca.key "$out"/router.crt "$out"/router.key "$out"/router.names \
    "$out"/users.txt "$out"/ca.srl "$out"/router.json5 "$out"/robots
fi

echo "make-secrets.sh: writing into $out"

# The CA.
if [[ -s "$out/ca.key" && -s "$out/ca.crt" ]]; then
  kept "$out/ca.crt"
else
  openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$out/ca.key" 2>/dev/null
  openssl req -x509 -new -key "$out/ca.key" -sha256 -days 3650 -subj "/CN=roam site CA" \
    -addext "basicConstraints=critical,CA:TRUE" \
    -addext "keyUsage=critical,keyCertSign,cRLSign" \
    -out "$out/ca.crt"
  rm -f "$out/router.crt"  # signed by the old CA, if any
  wrote "$out/ca.crt"
  wrote "$out/ca.key"
fi

# The router's certificate, with every name as a subject alternative name.
san=""
for name in "${names[@]}"; do
  if [[ "$name" =~ ^[0-9.]+$ || "$name" == *:* ]]; then
    san+="${san:+,}IP:$name"
  else
    san+="${san:+,}DNS:$name"
  fi
done
if [[ -s "$out/router.key" && -s "$out/router.crt" && "$(cat "$out/router.names" 2>/dev/null)" == "$san" ]]; then
  kept "$out/router.crt ($san)"
else
  [[ -s "$out/router.key" ]] ||
    openssl genpkey -algorithm EC -pkeyopt ec_paramgen_curve:P-256 -out "$out/router.key" 2>/dev/null
  openssl req -new -key "$out/router.key" -subj "/CN=${names[0]}" -out "$tmp/router.csr"
  cat >"$tmp/router.ext" <<EOF
basicConstraints=critical,CA:FALSE
keyUsage=critical,digitalSignature,keyEncipherment
extendedKeyUsage=serverAuth
subjectAltName=$san
EOF
  openssl x509 -req -in "$tmp/router.csr" -CA "$out/ca.crt" -CAkey "$out/ca.key" \
    -CAcreateserial -sha256 -days 825 -extfile "$tmp/router.ext" -out "$out/router.crt" 2>/dev/null
  echo "$san" >"$out/router.names"
  wrote "$out/router.crt ($san)"
  wrote "$out/router.key"
fi

# Passwords: keep the ones users.txt has, make the missing ones.
: >"$tmp/users.txt"
for user in "${users[@]}"; do
  [[ -n "${password[$user]:-}" ]] || password["$user"]="$(openssl rand -hex 24)"
  echo "$user:${password[$user]}" >>"$tmp/users.txt"
done
install_file users.txt "${#users[@]} users"
printf '%s\n' "${robots[@]}" | sed '/^$/d' >"$tmp/robots"
install_file robots "${#robots[@]} robots"

# One client config per user, from the template.
command_of() {
  case "$1" in
    operator) echo "roam map layers" ;;
    ros-node) echo "ros2 run ... (rmw_zenoh: merge into its session config)" ;;
    mission-*) echo "roam mission --robot ${1#mission-}" ;;
    controller-*) echo "roam controller --robot ${1#controller-}" ;;
    *) echo "roam $1" ;;
  esac
}
for user in "${users[@]}"; do
  sed -e "s|\"tls/router:7447\"|\"$connect\"|" \
    -e "s|\"/etc/roam/secrets/ca.crt\"|\"$install_dir/ca.crt\"|" \
    -e "s|user: \"ROLE\"|user: \"$user\"|" \
    -e "s|password: \"PASSWORD\"|password: \"${password[$user]}\"|" \
    -e "s|/etc/roam/secrets/<user>.json5 <command>|$install_dir/$user.json5 $(command_of "$user")|" \
    "$client_template" >"$tmp/$user.json5"
  grep -q "user: \"$user\"" "$tmp/$user.json5" ||
    { echo "make-secrets.sh: the template $client_template no longer has the placeholders" >&2; exit 1; }
  install_file "$user.json5"
done
# The users of the last run that are gone (a robot left the fleet): their configs too.
for user in "${old_users[@]}"; do
  if ! printf '%s\n' "${users[@]}" | grep -qxF "$user"; then
    rm -f "$out/$user.json5"
    echo "  removed $user ($out/$user.json5)"
  fi
done

# The router's config: the template, with each robot's rules at its `// @robots` lines.
robot_rules() {
  local r="$1"
  cat <<EOF
      // robot $r's executive (mission-$r): the clock, its robot's estimate and controller
      // status; its robot's mission, report and status; its robot's plans.
      {
        id: "mission_${r}_hear_in",
        messages: ["declare_subscriber"],
        flows: ["ingress"],
        permission: "allow",
        key_exprs: ["roam/sim/clock", "roam/robot/$r/estimate", "roam/robot/$r/controller"],
      },
      {
        id: "mission_${r}_hear_out",
        messages: ["put"],
        flows: ["egress"],
        permission: "allow",
        key_exprs: ["roam/sim/clock", "roam/robot/$r/estimate", "roam/robot/$r/controller"],
      },
      {
        id: "mission_${r}_drive_in",
        messages: ["put"],
        flows: ["ingress"],
        permission: "allow",
        key_exprs: ["roam/robot/$r/mission", "roam/robot/$r/mission_report", "roam/robot/$r/executive"],
      },
      {
        id: "mission_${r}_plan_in",
        messages: ["query"],
        flows: ["ingress"],
        permission: "allow",
        key_exprs: ["roam/planner/robot/$r/plan", "roam/planner/instance/*/robot/$r/plan"],
      },
      {
        id: "mission_${r}_plan_out",
        messages: ["reply"],
        flows: ["egress"],
        permission: "allow",
        key_exprs: ["roam/planner/robot/$r/plan", "roam/planner/instance/*/robot/$r/plan"],
      },
      {
        id: "mission_${r}_cancel_in",
        messages: ["put"],
        flows: ["ingress"],
        permission: "allow",
        key_exprs: ["roam/planner/robot/$r/cancel/*"],
      },
      // robot $r's controller (controller-$r): its robot's mission and estimate in, its
      // robot's commands and status out.
      {
        id: "controller_${r}_hear_in",
        messages: ["declare_subscriber"],
        flows: ["ingress"],
        permission: "allow",
        key_exprs: ["roam/robot/$r/mission", "roam/robot/$r/estimate"],
      },
      {
        id: "controller_${r}_hear_out",
        messages: ["put"],
        flows: ["egress"],
        permission: "allow",
        key_exprs: ["roam/robot/$r/mission", "roam/robot/$r/estimate"],
      },
      {
        id: "controller_${r}_drive_in",
        messages: ["put"],
        flows: ["ingress"],
        permission: "allow",
        key_exprs: ["roam/robot/$r/cmd", "roam/robot/$r/controller"],
      },
EOF
}
robot_subjects() {
  echo "      { id: \"mission-$1\", usernames: [\"mission-$1\"] },"
  echo "      { id: \"controller-$1\", usernames: [\"controller-$1\"] },"
}
robot_policies() {
  local r="$1"
  cat <<EOF
      {
        id: "mission-$r",
        subjects: ["mission-$r"],
        rules: [
          "mission_${r}_hear_in", "mission_${r}_hear_out", "mission_${r}_drive_in",
          "mission_${r}_plan_in", "mission_${r}_plan_out", "mission_${r}_cancel_in",
          "map_read_in", "map_read_out", "plan_ask_in_live", "plan_ask_out_live", "live_mission",
        ],
      },
      {
        id: "controller-$r",
        subjects: ["controller-$r"],
        rules: [
          "controller_${r}_hear_in", "controller_${r}_hear_out", "controller_${r}_drive_in",
          "map_index_in", "map_index_out", "live_controller",
        ],
      },
EOF
}
for part in rules subjects policies; do
  echo "      // generated by make-secrets.sh for the robots: ${robots[*]:-none}" >"$tmp/$part"
  for robot in "${robots[@]}"; do "robot_$part" "$robot" >>"$tmp/$part"; done
done
grep -c '// @robots: \(rules\|subjects\|policies\)$' "$template" | grep -qx 3 ||
  { echo "make-secrets.sh: the template $template no longer has its three // @robots lines" >&2; exit 1; }
awk -v dir="$tmp" '
  / \/\/ @robots: (rules|subjects|policies)$/ {
    part = $NF
    while ((getline line < (dir "/" part)) > 0) print line
    next
  }
  { print }
' "$template" |
  sed -e "s|/etc/roam/secrets/|$install_dir/|g" \
    -e "s|\"0/|\"$ros_domain/|g" -e "s|\"@ros2_lv/0/|\"@ros2_lv/$ros_domain/|g" \
    >"$tmp/router.json5"
install_file router.json5 "robots: ${robots[*]:-none}; ROS domain $ros_domain"

echo "done. Copy to $install_dir on the router: ca.crt router.crt router.key users.txt"
echo "router.json5 (ZENOH_CONFIG=$install_dir/router.json5 roam router); on each machine:"
echo "ca.crt and its users' <user>.json5 (ZENOH_CONFIG=$install_dir/<user>.json5)."
