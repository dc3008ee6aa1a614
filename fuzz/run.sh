#!/usr/bin/env bash
# Runs every fuzz target for SECONDS (default 600) each, two at a time, with the corpus in
# fuzz/corpus/<target> (new inputs are added there) and crashes in fuzz/artifacts/<target>.
# Needs cargo-fuzz (`cargo install cargo-fuzz`); on a stable toolchain RUSTC_BOOTSTRAP=1 lets it
# use the sanitizer flags it needs.
set -euo pipefail
cd "$(dirname "$0")"
SECONDS_EACH="${1:-600}"
export RUSTC_BOOTSTRAP=1
cargo fuzz build -O
run() {
    cargo fuzz run -O "$1" "corpus/$1" -- -max_total_time="$SECONDS_EACH" -timeout=30 -max_len=65536 \
        -print_final_stats=1 >"logs/$1.log" 2>&1 || echo "$1: crashed, see logs/$1.log and artifacts/$1"
}
mkdir -p logs
run scene & run urdf & wait
run mesh & run checkpoint & wait
run gltf_skin
for t in scene urdf mesh checkpoint gltf_skin; do
    echo "$t: $(grep -E '^stat::number_of_executed_units' "logs/$t.log" | tail -1) $(grep -c 'ERROR: ' "logs/$t.log" || true) errors"
done
