// SPDX-License-Identifier: MIT
// The one entry point of hbvh_bench: every bench/*.cpp registers its benchmarks, this runs them. A
// benchmark that finds a wrong answer (bench::fail) makes the run exit 1, so that a timing run cannot
// hide a broken method; Google Benchmark itself exits 0 after SkipWithError.
#include <benchmark/benchmark.h>

#include <string>

namespace hbvh::bench {
namespace {
bool any_failure = false;
}  // namespace

/// Declared where it is used (bench_query.cpp): marks the benchmark as failed and the run as failing.
void fail(benchmark::State& state, const std::string& message) {
    state.SkipWithError(message.c_str());
    any_failure = true;
}

}  // namespace hbvh::bench

int main(int argc, char** argv) {
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return hbvh::bench::any_failure ? 1 : 0;
}
