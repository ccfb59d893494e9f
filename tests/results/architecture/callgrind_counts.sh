#!/usr/bin/env bash
# Counts the instructions of one iteration of each solver and flock benchmark under callgrind, on one CPU
# (taskset: TBB then starts no worker threads, whose spinning made the flock steps' counts differ by up to a
# quarter between runs of one binary), one run per benchmark; prints "benchmark,side,instructions,iterations"
# (the inclusive count of the benchmark's function, which holds its fixture's setup and the one iteration
# --benchmark_min_time=0.000001 gives; the iterations column is the benchmark's own report of them).
# Usage: tests/results/architecture/callgrind_counts.sh KEYFRAME_BENCH SIDE TREE [BENCHMARK...]
# TREE: a checkout whose build/release/ is the working directory (the figure benchmarks read ../../scenes/).
bin=$1; side=$2; tree=$3; shift 3
list=${*:-BM_ClothStep/16 BM_ClothStep/32 BM_ClothStepAdjoint/16 BM_ClothAssemble/32 BM_FlockStep/200/1/0 BM_FlockStep/1000/1/0 BM_FlockStepAdjoint/200/1/0 BM_FlockStepAdjoint/1000/1/0 BM_Flock200Forward BM_Flock200Gradient}
work=$(mktemp -d)
mkdir -p "$tree/build/release" && cd "$tree/build/release" || exit 2
for b in $list; do
  out=$work/$(echo "$b" | tr / _)
  OMP_NUM_THREADS=1 nice -n 10 taskset -c 0 valgrind --tool=callgrind --callgrind-out-file="$out.cg" "$bin" \
    --benchmark_filter="^$b\$" --benchmark_min_time=0.000001 > "$out.log" 2>&1
  fn=$(echo "$b" | cut -d/ -f1)
  ir=$(callgrind_annotate --inclusive=yes "$out.cg" 2>/dev/null | grep -E "::$fn\(|[ :]$fn\(" | head -1 | awk '{print $1}' | tr -d ,)
  iters=$(grep -E "^$b " "$out.log" | awk '{print $6}')
  echo "$b,$side,$ir,$iters"
done
rm -rf "$work"
