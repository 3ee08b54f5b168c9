#!/usr/bin/env bash
# Checks that pgo/pathlight-cpu.profdata, the profile pathlight-cpu's release build is optimised
# with (tools/rustc-pgo), was made from the CPU backend as it is: rustc discards the counts of
# every function whose code changed since (the whole row renderer when any function it
# inlines did) and warns "hash mismatch". Builds the release binary and fails, naming them,
# when it warned so, or when tools/rustc-pgo left the profile out (made by a newer LLVM).
#
#   tools/check-pgo.sh
set -euo pipefail
cd "$(dirname "$0")/.."

if [ ! -f pgo/pathlight-cpu.profdata ]; then
    echo "pgo/pathlight-cpu.profdata is missing: run tools/pgo.sh" >&2
    exit 1
fi
# A build that is up to date repeats the warnings of the one that compiled the crate.
log=$(cargo build --release --locked -p pathlight 2>&1) || {
    echo "$log" >&2
    exit 1
}
if grep -q "pathlight-cpu built without" <<<"$log"; then
    grep "pathlight-cpu built without" <<<"$log" >&2
    exit 1
fi
stale=$(grep -o "hash mismatch) [^ ]*" <<<"$log" | cut -d" " -f3 | c++filt | sort -u || true)
if [ -n "$stale" ]; then
    echo "pgo/pathlight-cpu.profdata was made before these functions changed; run tools/pgo.sh" >&2
    echo "and commit the profile with the change:" >&2
    echo "$stale" >&2
    exit 1
fi
echo "pgo/pathlight-cpu.profdata is up to date with the CPU backend"
