#!/usr/bin/env bash
# Builds the roam container image (deploy/container/Containerfile) FROM scratch: the
# stripped release binary, exactly the shared libraries `ldd` names (at their absolute
# paths) and the repository's config/ as /usr/share/roam. Works from any directory.
#
#   deploy/container/build-image.sh                        cargo build --release --locked -p roam, then the image
#   deploy/container/build-image.sh --bin target/release/roam   use this binary, build nothing
#   ROAM_BIN=path ROAM_IMAGE=roam:dev deploy/container/build-image.sh
#
# Options (or the environment variable in brackets):
#   --bin PATH       an existing roam binary; default: build it with cargo [ROAM_BIN]
#   --tag TAG        the image tag, default roam:latest [ROAM_IMAGE]
#   --engine NAME    podman or docker; default: podman if installed, else docker [ROAM_ENGINE]
# With podman on a host where crun does not work, export CONTAINERS_CONF=$PWD/deploy/containers.conf.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"

bin="${ROAM_BIN:-}"
tag="${ROAM_IMAGE:-roam:latest}"
engine="${ROAM_ENGINE:-}"

usage() { sed -n '2,16p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; }

while [ $# -gt 0 ]; do
    case "$1" in
        --bin) bin="${2:?--bin needs a path}"; shift 2 ;;
        --tag) tag="${2:?--tag needs a tag}"; shift 2 ;;
        --engine) engine="${2:?--engine needs podman or docker}"; shift 2 ;;
        -h|--help) usage; exit 0 ;;
        *) echo "build-image.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
    esac
done

if [ -z "$engine" ]; then
    if command -v podman >/dev/null 2>&1; then
        engine=podman
    elif command -v docker >/dev/null 2>&1; then
        engine=docker
    else
        echo "build-image.sh: neither podman nor docker is installed" >&2
        exit 1
    fi
fi
command -v "$engine" >/dev/null 2>&1 || { echo "build-image.sh: '$engine' is not installed" >&2; exit 1; }
for tool in ldd strip; do
    command -v "$tool" >/dev/null 2>&1 || { echo "build-image.sh: '$tool' is needed (binutils, libc-bin)" >&2; exit 1; }
done

if [ -z "$bin" ]; then
    echo "build-image.sh: cargo build --release --locked -p roam" >&2
    (cd "$repo" && cargo build --release --locked -p roam)
    bin="$repo/target/release/roam"
fi
case "$bin" in /*) ;; *) bin="$PWD/$bin" ;; esac
[ -x "$bin" ] || { echo "build-image.sh: no executable at $bin" >&2; exit 1; }

ctx="$(mktemp -d "${TMPDIR:-/tmp}/roam-image.XXXXXX")"
trap 'rm -rf "$ctx"' EXIT
rootfs="$ctx/rootfs"
mkdir -p "$rootfs/usr/local/bin" "$rootfs/usr/share" "$rootfs/tmp" "$ctx/state/map" "$ctx/state/sim"
chmod 1777 "$rootfs/tmp"

strip --strip-all -o "$rootfs/usr/local/bin/roam" "$bin"
chmod 0755 "$rootfs/usr/local/bin/roam"

# Every library the dynamic linker resolves, at the path it resolves it to, plus the
# interpreter itself; linux-vdso has no file. cp -L copies the target of a symlink under
# the name the binary asks for.
libs=()
if ldd_out="$(ldd "$bin" 2>&1)"; then
    if grep -q 'not found' <<<"$ldd_out"; then
        echo "build-image.sh: ldd cannot resolve every library of $bin:" >&2
        echo "$ldd_out" >&2
        exit 1
    fi
    while read -r first arrow target _; do
        if [ "$arrow" = "=>" ] && [ "${target#/}" != "$target" ]; then
            libs+=("$target")
        elif [ "${first#/}" != "$first" ]; then
            libs+=("$first")
        fi
    done <<<"$ldd_out"
elif grep -q 'not a dynamic executable' <<<"$ldd_out"; then
    echo "build-image.sh: $bin is static; no libraries to copy" >&2
else
    echo "build-image.sh: ldd $bin failed: $ldd_out" >&2
    exit 1
fi
for lib in "${libs[@]}"; do
    mkdir -p "$rootfs$(dirname "$lib")"
    cp -L "$lib" "$rootfs$lib"
done

cp -R "$repo/config" "$rootfs/usr/share/roam"
cp "$here/Containerfile" "$ctx/Containerfile"

version="$("$bin" --version 2>/dev/null | awk '{print $2}')"
previous="$("$engine" image inspect --format '{{.Id}}' "$tag" 2>/dev/null || true)"
engine_args=()
# podman: no intermediate images per step (the build takes a second anyway).
[ "$engine" = podman ] && engine_args=(--layers=false)
echo "build-image.sh: $engine build -t $tag (roam ${version:-?}; libraries: ${libs[*]:-none})" >&2
"$engine" build "${engine_args[@]}" -f "$ctx/Containerfile" -t "$tag" \
    --label "org.opencontainers.image.title=roam" \
    --label "org.opencontainers.image.version=${version:-unknown}" \
    --label "org.opencontainers.image.source=roam repository, deploy/container" \
    "$ctx"
# The image the tag named before is now untagged: remove it unless something still uses it.
current="$("$engine" image inspect --format '{{.Id}}' "$tag" 2>/dev/null || true)"
if [ -n "$previous" ] && [ "$previous" != "$current" ]; then
    "$engine" rmi "$previous" >/dev/null 2>&1 || true
fi
"$engine" image inspect --format '{{.Size}}' "$tag" 2>/dev/null |
    awk -v t="$tag" '{printf "build-image.sh: %s is %.1f MB\n", t, $1 / 1e6}' >&2 || true
