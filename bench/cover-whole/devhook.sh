#!/usr/bin/env bash
# Build `devhook/` for `h100-parts.sh` on this machine: this tree's release
# `strata` and `pipeline_stats` with the shader-rewrite hook
# (STRATA_SHADER_SED_FILE; without it the binary is this tree's), stripped,
# `strata` xz-compressed (the tree that travels is at most 64 MiB). The
# hook's patches are applied to the work tree for the build and taken off
# after, so commit or stash first.   bash bench/cover-whole/devhook.sh
set -eu
cd "$(git rev-parse --show-toplevel)"
patches="bench/ray-exact-ablation/round2/shader-sed-hook.patch bench/cover-whole/pipeline-stats-sed-hook.patch"
for p in $patches; do git apply "$p"; done
trap 'for p in $patches; do git apply -R "$p"; done' EXIT
cargo build --release -p strata
cargo build --release -p strata-render --example pipeline_stats
mkdir -p devhook
strip -o devhook/strata target/release/strata
xz -T0 -6 -f devhook/strata
strip -o devhook/pipeline_stats target/release/examples/pipeline_stats
git rev-parse HEAD > devhook/commit
ls -la devhook
