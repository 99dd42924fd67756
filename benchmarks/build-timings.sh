#!/usr/bin/env bash
# Build-time figures for benchmarks/build-timings.md: a clean `cargo build` (default members,
# dev profile) with --timings, then a fusion edit and its crate's unit tests rebuilt.
#
# usage: benchmarks/build-timings.sh CHECKOUT CRATE FUSION_FILE
#   e.g. benchmarks/build-timings.sh . phantogram-sensing core/sensing/src/fusion/mod.rs
# Builds into CHECKOUT/target-timing (removed first); the HTML reports are copied to
# CHECKOUT/target-timing/*.html. Run on a quiet machine: the figures are wall-clock seconds.
set -euo pipefail
cd "$1"
crate="$2"
fusion="$3"
export CARGO_TARGET_DIR="$PWD/target-timing"
rm -rf "$CARGO_TARGET_DIR"
t() { local s; s=$(date +%s.%N); "$@" >/dev/null 2>&1; echo "$(date +%s.%N) - $s" | bc; }
echo "clean cargo build: $(t cargo build --timings) s"
cp "$CARGO_TARGET_DIR"/cargo-timings/cargo-timing.html "$CARGO_TARGET_DIR/clean.html"
echo "first unit-test build of $crate: $(t cargo test -p "$crate" --lib --no-run) s"
# A real edit (a new function), not a comment: incremental compilation skips a comment at once.
echo '#[allow(dead_code)] fn timing_probe() -> u64 { std::hint::black_box(7) }' >> "$fusion"
echo "after an edit to $fusion, unit-test build of $crate: $(t cargo test -p "$crate" --lib --no-run --timings) s"
sed -i '$ d' "$fusion"
cp "$CARGO_TARGET_DIR"/cargo-timings/cargo-timing.html "$CARGO_TARGET_DIR/incremental.html"
echo "and running them: $(t cargo test -p "$crate" --lib) s"
echo "crates in $crate's unit-test build: $(cargo tree -p "$crate" -e normal,dev --prefix none | sort -u | wc -l)"
