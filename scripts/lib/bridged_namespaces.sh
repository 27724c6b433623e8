# Network namespaces joined by one bridge, as devices on one LAN (sourced by scripts/lossy_link
# and scripts/readme_walkthrough; root only).
#
#   namespaces_up BRIDGE PREFIX SUBNET NAME...
#     makes the bridge BRIDGE and, for each NAME, the namespace PREFIX<NAME> joined to it by the
#     veth pair PREFIXv<NAME> (inside) / PREFIXv<NAME>p (on the bridge), with the address
#     SUBNET.k/24 (k = 1, 2, ... in the order given), loopback up and a route for multicast, which
#     Fast DDS's discovery uses. Returns non-zero at the first step that fails.
#   namespaces_down BRIDGE PREFIX NAME...
#     stops what runs in them and removes them and the bridge; never fails.

namespaces_up() {
  local br=$1 prefix=$2 subnet=$3 k=0 name ns v
  shift 3
  ip link add "$br" type bridge && ip link set "$br" up || return 1
  for name in "$@"; do
    k=$((k + 1)) ns=$prefix$name v=${prefix}v$name
    ip netns add "$ns" && ip link add "$v" type veth peer name "${v}p" || return 1
    ip link set "${v}p" master "$br" && ip link set "${v}p" up && ip link set "$v" netns "$ns" || return 1
    ip netns exec "$ns" ip addr add "$subnet.$k/24" dev "$v" &&
      ip netns exec "$ns" ip link set "$v" up &&
      ip netns exec "$ns" ip link set lo up &&
      ip netns exec "$ns" ip route add 224.0.0.0/4 dev "$v" || return 1
  done
}

namespaces_down() {
  local br=$1 prefix=$2 name
  shift 2
  for name in "$@"; do ip netns pids "$prefix$name" 2>/dev/null | xargs -r kill 2>/dev/null || true; done
  for name in "$@"; do ip netns del "$prefix$name" 2>/dev/null || true; done
  ip link del "$br" 2>/dev/null || true
}
