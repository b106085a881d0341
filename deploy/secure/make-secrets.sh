#!/usr/bin/env bash
# Makes the secrets of a secure roam site with the openssl CLI:
#
#   ca.crt, ca.key           a site CA (10 years)
#   router.crt, router.key   the router's TLS certificate, signed by the CA (825 days), with
#                            the given names as subject alternative names
#   users.txt                Zenoh's user/password dictionary: one `user:password` line per
#                            role, random passwords
#   <role>.json5             one Zenoh client config per role (deploy/secure/client.json5
#                            with that role's user, password, CA path and router endpoint)
#
# Usage: deploy/secure/make-secrets.sh [--out DIR] [--install-dir DIR] [--connect ENDPOINT]
#                                      [--force] [NAME ...]
#
#   NAME           a DNS name or an IP address of the router (default: router localhost
#                  127.0.0.1); clients must connect with one of them
#   --out          where to write (default: deploy/secure/secrets/, git-ignored)
#   --install-dir  where the files will live on the machines, written into the configs
#                  (default: /etc/roam/secrets, as router.json5 expects)
#   --connect      the router endpoint in the role configs (default: tls/<first NAME>:7447)
#   --force        make everything anew (new CA, new passwords)
#
# Run again, it keeps the CA, the keys and the passwords it finds and only makes what is
# missing (a router certificate is remade when its names change); the role configs are
# remade from users.txt and the template when they differ. Everything is written readable
# by the owner only.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
out="$here/secrets"
install_dir="/etc/roam/secrets"
connect=""
force=0
names=()

while [[ $# -gt 0 ]]; do
  case "$1" in
    --out) out="${2:?--out needs a directory}"; shift 2 ;;
    --install-dir) install_dir="${2:?--install-dir needs a directory}"; shift 2 ;;
    --connect) connect="${2:?--connect needs an endpoint, e.g. tls/router:7447}"; shift 2 ;;
    --force) force=1; shift ;;
    -h|--help) sed -n '2,26p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "make-secrets.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) names+=("$1"); shift ;;
  esac
done
[[ ${#names[@]} -gt 0 ]] || names=(router localhost 127.0.0.1)
[[ -n "$connect" ]] || connect="tls/${names[0]}:7447"

# The roles of router.json5's access control, one user each.
roles=(map-server planner localization controller mapper mission sim operator)

command -v openssl >/dev/null || { echo "make-secrets.sh: needs the openssl CLI" >&2; exit 1; }
umask 077
mkdir -p "$out"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

wrote() { echo "  wrote $1"; }
kept() { echo "  kept  $1"; }

if [[ $force -eq 1 ]]; then
  rm -f "$out"/ca.crt "$out"/ca.key "$out"/router.crt "$out"/router.key "$out"/router.names \
    "$out"/users.txt "$out"/ca.srl
  for role in "${roles[@]}"; do rm -f "$out/$role.json5"; done
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
declare -A password=()
if [[ -f "$out/users.txt" ]]; then
  while IFS=: read -r user pass; do
    [[ -n "$user" && -n "$pass" ]] && password["$user"]="$pass"
  done <"$out/users.txt"
fi
: >"$tmp/users.txt"
for role in "${roles[@]}"; do
  [[ -n "${password[$role]:-}" ]] || password["$role"]="$(openssl rand -hex 24)"
  echo "$role:${password[$role]}" >>"$tmp/users.txt"
done
if cmp -s "$tmp/users.txt" "$out/users.txt" 2>/dev/null; then
  kept "$out/users.txt"
else
  cp "$tmp/users.txt" "$out/users.txt"
  wrote "$out/users.txt (${#roles[@]} users)"
fi

# One client config per role, from the template.
template="$here/client.json5"
[[ -f "$template" ]] || { echo "make-secrets.sh: missing $template" >&2; exit 1; }
for role in "${roles[@]}"; do
  command="roam $role"
  [[ "$role" != operator ]] || command="roam map layers"
  sed -e "s|\"tls/router:7447\"|\"$connect\"|" \
    -e "s|\"/etc/roam/secrets/ca.crt\"|\"$install_dir/ca.crt\"|" \
    -e "s|user: \"ROLE\"|user: \"$role\"|" \
    -e "s|password: \"PASSWORD\"|password: \"${password[$role]}\"|" \
    -e "s|/etc/roam/secrets/controller.json5 roam controller|$install_dir/$role.json5 $command|" \
    "$template" >"$tmp/$role.json5"
  grep -q "user: \"$role\"" "$tmp/$role.json5" ||
    { echo "make-secrets.sh: the template $template no longer has the placeholders" >&2; exit 1; }
  if cmp -s "$tmp/$role.json5" "$out/$role.json5" 2>/dev/null; then
    kept "$out/$role.json5"
  else
    cp "$tmp/$role.json5" "$out/$role.json5"
    wrote "$out/$role.json5"
  fi
done

echo "done. Copy to $install_dir on the router: ca.crt router.crt router.key users.txt;"
echo "on each role's machine: ca.crt and <role>.json5 (ZENOH_CONFIG=$install_dir/<role>.json5)."
