#!/usr/bin/env bash
# Expansion time of `pkm::mechanism!` in a user's default debug build.
#
#   bash benches/user-crate/measure.sh [RUNS] [NAME…]
#
# 1. `expand_time`: pkm-dsl's `expand` (the macro's whole body) timed in this
#    crate's debug profile, where pkm-dsl is built at opt-level 0 as the
#    proc-macro is in a user's build; min and median of RUNS per mechanism.
# 2. End to end, for each NAME (default seed000_a): `cargo build` of this
#    crate with that one mechanism minus the same build with none, best of
#    RUNS. It also includes type-checking and compiling the generated code.
set -euo pipefail
cd "$(dirname "$0")"
runs=${1:-5}
shift || true
# Resolve dependencies as the workspace does.
[ -f Cargo.lock ] || cp ../../Cargo.lock .
cargo build -q --bin expand_time --features compiler
"${CARGO_TARGET_DIR:-target}"/debug/expand_time "$runs" "$@"

best() { # best wall time in seconds of `cargo build --lib` with features $1
    local t min=
    for _ in $(seq "$runs"); do
        touch src/lib.rs
        local start=$(date +%s.%N)
        cargo build -q --lib ${1:+--features "$1"}
        t=$(echo "$start $(date +%s.%N)" | awk '{print $2 - $1}')
        min=$(echo "${min:-$t} $t" | awk '{print ($2 < $1) ? $2 : $1}')
    done
    echo "$min"
}
echo
echo "end to end: cargo build --lib with one mechanism minus with none (best of $runs)"
empty=$(best "")
for name in "${@:-seed000_a}"; do
    one=$(best "$name")
    echo "$name $one $empty" | awk '{printf "%-24s %6.0f ms\n", $1, 1000 * ($2 - $3)}'
done
