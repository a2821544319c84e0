# Sourced by the integration scripts: a private network namespace, and metrics.json's figures.

# semx_private_netns "$0" "$@": as root, runs the calling script again with the same arguments in
# a private network namespace (multicast on loopback), so no other process set on the machine
# hears its sets or is heard by them. Returns, and the script goes on here, when not root, when
# unshare is missing, or inside such a namespace already (SEMX_IN_PRIVATE_NETNS).
semx_private_netns() {
  [ -z "${SEMX_IN_PRIVATE_NETNS:-}" ] && [ "$(id -u)" -eq 0 ] && command -v unshare >/dev/null || return 0
  SEMX_IN_PRIVATE_NETNS=1 exec unshare --net bash -c \
    'ip link set lo up; ip route add 224.0.0.0/4 dev lo; exec "$0" "$@"' "$@"
}

# json FILE KEY: a top-level scalar of a metrics.json, without quotes.
json() { sed -n "s/^  \"$2\": \\(.*\\),\$/\\1/p" "$1" | tr -d '"'; }
