// SPDX-License-Identifier: MIT
// The one entry point of hbvh_bench: every bench/*.cpp registers its benchmarks, this runs them.
#include <benchmark/benchmark.h>

BENCHMARK_MAIN();
