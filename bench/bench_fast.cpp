// SPDX-License-Identifier: MIT
// The speed preset: build_fast's time per build and its tree's Eq. 2 cost relative to auto's, without the quick
// treelet sweep and with 4-6 units per treelet (FastOptions::treelet_units), and for 0, 2, 4 and 8 refitted
// nodes (FastOptions::exact_fits), with and without the root's look-ahead (FastOptions::lookahead_candidates), on the
// bundled models and generated objects of 30 primitives. The defaults (5 units, 2 refits, 6 candidates) are chosen
// from this table and the peers' objects (docs/fast.md).
#include <benchmark/benchmark.h>

#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "hbvh/builders/auto.hpp"
#include "hbvh/builders/context.hpp"
#include "hbvh/builders/fast.hpp"
#include "hbvh/io/xml.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/stats.hpp"

namespace hbvh {
namespace {

/// The objects: the bundled models and two generated objects of 30 primitives.
const char* const object_names[] = {"chair", "helicopter", "cannon", "tie_interceptor", "generated-30-7", "generated-30-8"};

/// An object's primitives and auto's cost over them, made on first use (auto takes about a second) and kept,
/// so that filtered runs load only what they measure and registration at static-initialisation time reads
/// nothing. Empty primitives: the model file is missing.
struct FastObject {
    std::vector<Primitive> primitives;
    double auto_cost = 0.0;
};

const FastObject& object_for(const std::string& name) {
    static std::map<std::string, FastObject> cache;
    auto [slot, inserted] = cache.try_emplace(name);
    if (!inserted) return slot->second;
    FastObject& object = slot->second;
    if (name.starts_with("generated-30-")) {
        object.primitives = generate_scene({.count = 30, .seed = std::stoull(name.substr(13))});
    } else {
        const Result<XmlModel> xml = read_xml_file(std::filesystem::path(HBVH_SOURCE_DIR) / "data/models" / (name + ".xml"));
        if (xml) object.primitives = xml->primitives;
    }
    if (!object.primitives.empty()) object.auto_cost = cost(build_auto(object.primitives, BuildContext{}).value());
    return object;
}

void fast_build(benchmark::State& state, const std::string& name, const FastOptions& options) {
    const FastObject& object = object_for(name);
    if (object.primitives.empty()) {
        state.SkipWithError(("cannot read data/models/" + name + ".xml").c_str());
        return;
    }
    const BuildContext context;
    double tree_cost = 0.0;
    for (auto _ : state) {
        Result<Bvh> bvh = build_fast(object.primitives, context, options);
        tree_cost = cost(bvh.value());
        benchmark::DoNotOptimize(tree_cost);
    }
    state.counters["cost"] = tree_cost;
    state.counters["cost_vs_auto"] = tree_cost / object.auto_cost;
}

/// Rows FastBuild/NAME/treelets:U/refits:R/lookahead:L: U units per quick treelet (0: no sweep), R refitted nodes,
/// L candidate cuts of the root's look-ahead (0: the greedy cut).
void register_fast_benchmarks() {
    constexpr FastOptions defaults;
    const std::uint32_t units = defaults.treelet_units, refits = defaults.exact_fits, lookahead = defaults.lookahead_candidates;
    const std::array<std::array<std::uint32_t, 3>, 8> settings{{{0, refits, lookahead},
                                                                {4, refits, lookahead},
                                                                {units, 0, lookahead},
                                                                {units, refits, lookahead},
                                                                {units, 4, lookahead},
                                                                {units, 8, lookahead},
                                                                {6, refits, lookahead},
                                                                {units, refits, 0}}};
    for (const char* name : object_names)
        for (const auto& [treelet_units, exact_fits, candidates] : settings) {
            const FastOptions options{.treelet_units = treelet_units, .exact_fits = exact_fits, .lookahead_candidates = candidates};
            benchmark::RegisterBenchmark(("FastBuild/" + std::string(name) + "/treelets:" + std::to_string(treelet_units) +
                                          "/refits:" + std::to_string(exact_fits) + "/lookahead:" + std::to_string(candidates))
                                             .c_str(),
                                         [name = std::string(name), options](benchmark::State& state) {
                                             fast_build(state, name, options);
                                         })
                ->Unit(benchmark::kMillisecond);
        }
}

/// Registers at static-initialisation time, before BENCHMARK_MAIN parses the command line.
const bool fast_benchmarks_registered = (register_fast_benchmarks(), true);

}  // namespace
}  // namespace hbvh
