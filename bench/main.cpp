// SPDX-License-Identifier: MIT
// The one entry point of hbvh_bench: every bench/*.cpp registers its benchmarks, this runs them. A
// benchmark that finds a wrong answer (bench::fail) makes the run exit 1, so that a timing run cannot
// hide a broken method; Google Benchmark itself exits 0 after SkipWithError.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <string>

#include "hbvh/io/xml_memory.hpp"

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
    // As the CLI does (apps/hbvh/main.cpp), so that the XML rows time what `hbvh` pays. With
    // HBVH_BENCH_XML_MALLOC set, pugixml keeps malloc: the rows then time a program that did not opt in.
    if (std::getenv("HBVH_BENCH_XML_MALLOC") == nullptr) hbvh::use_huge_pages_for_xml();
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return hbvh::bench::any_failure ? 1 : 0;
}
