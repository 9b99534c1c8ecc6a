#!/usr/bin/env bash
# The trace plots of docs/homing.md: one homing per family, recorded with
# `motionctl trace` against a running daemon (docs/plots.toml).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --workspace --bins >/dev/null
bin=target/release
$bin/motion-supervisor run --config docs/plots.toml 2>/dev/null &
daemon=$!
trap 'kill -TERM $daemon 2>/dev/null; wait $daemon 2>/dev/null || true' EXIT
for _ in $(seq 100); do $bin/motionctl --config docs/plots.toml status >/dev/null 2>&1 && break; sleep 0.1; done
sleep 0.5
for axis in switch marker switch_then_marker torque torque_then_marker unidirectional \
        limit_switch limit_switch_then_marker reverse_at_limit; do
    $bin/motionctl --config docs/plots.toml trace "$axis" --home \
        --out "docs/plots/$axis.csv" --plot "docs/plots/$axis.svg"
done
rm -f docs/plots/*.csv
