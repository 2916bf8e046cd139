#!/usr/bin/env bash
# Cross-check `salient info` against PrusaSlicer's `--info` on one model: the same facet count
# after repair, the same number of open edges, and the same verdict on manifoldness.
# Usage: peer_info_check.sh SALIENT MODEL
set -euo pipefail
salient=$1 model=$2
ours=$("$salient" info "$model" --json)
theirs=$(prusa-slicer --info "$model" 2>/dev/null)
field() { sed -n "s/^$1 = *//p" <<<"$theirs" | head -1; }
jq_num() { grep -o "\"$1\": [0-9]*" <<<"$ours" | grep -o '[0-9]*$'; }
facets=$(field number_of_facets) open=$(field open_edges) manifold=$(field manifold)
[[ -n "$facets" ]] || { echo "PrusaSlicer printed no facet count"; exit 1; }
status=0
[[ "$(jq_num triangles)" == "$facets" ]] || { echo "triangles: ours $(jq_num triangles), PrusaSlicer $facets"; status=1; }
[[ "$(jq_num boundary_edges)" == "${open:-0}" ]] || { echo "open edges: ours $(jq_num boundary_edges), PrusaSlicer ${open:-0}"; status=1; }
watertight=$(grep -o '"watertight": [a-z]*' <<<"$ours" | grep -o '[a-z]*$')
[[ ( "$watertight" == true && "$manifold" == yes ) || ( "$watertight" == false && "$manifold" == no ) ]] ||
  { echo "watertight: ours $watertight, PrusaSlicer manifold = $manifold"; status=1; }
[[ $status == 0 ]] && echo "agrees with PrusaSlicer: $facets facets, ${open:-0} open edges, manifold $manifold"
exit $status
