#!/usr/bin/env bash
# The bench's thread and GPU rows on a larger machine: the threads rows on 1, 2, 4, … threads
# up to its cores beside the work split's prediction (`scaling`), and each frame on its GPU
# (`gpu`, `cost`: wgpu picks the machine's Vulkan adapter). One prebuilt binary, no network.
#
#   cargo build --release --features gpu,mimalloc
#   tools/bench-many-cores.sh [BINARY] [OUTPUT_FOLDER]
#
# Writes machine.txt (cores, CPU, GPU), bench.csv (every row) and bench.txt (the printed table).
set -euo pipefail
bin=${1:-target/release/stereolab}
out=${2:-target/bench-many-cores}
[ -x "$bin" ] || { echo "no stereolab binary at $bin: build it with cargo build --release --features gpu,mimalloc" >&2; exit 2; }
mkdir -p "$out"
{
    echo "cores: $(nproc)"
    lscpu | grep -E '^(Model name|Socket|Core|Thread|NUMA node\(s\)|L3)' || true
    if command -v nvidia-smi >/dev/null; then nvidia-smi -L; else echo "gpu: no nvidia-smi"; fi
} > "$out/machine.txt"
"$bin" bench --only scaling,gpu,cost --csv "$out/bench.csv" 2>&1 | tee "$out/bench.txt"
