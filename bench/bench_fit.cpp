// SPDX-License-Identifier: MIT
// OBB fitting on the bundled models: hbvh's multi-candidate fit_obb against Gottschalk's covariance
// method alone (the survey's fitter). Counters give the volumes; the time is the fit itself.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>

#include "hbvh/fit/fit.hpp"
#include "hbvh/io/xml.hpp"

namespace hbvh {
namespace {

/// Every pair of primitives and the whole set: the groups a bottom-up builder fits most often,
/// and the root.
std::vector<FitInput> fit_sets(const std::vector<Primitive>& primitives) {
    std::vector<FitInput> sets;
    FitInput all;
    for (const Primitive& p : primitives) all.add(p.volume);
    sets.push_back(all);
    for (std::size_t i = 0; i < primitives.size(); ++i)
        for (std::size_t j = i + 1; j < primitives.size(); ++j) {
            FitInput pair;
            pair.add(primitives[i].volume);
            pair.add(primitives[j].volume);
            sets.push_back(pair);
        }
    return sets;
}

void fit_obb_on_model(benchmark::State& state, const std::string& model, bool covariance_only) {
    auto xml = read_xml_file(std::filesystem::path(HBVH_SOURCE_DIR) / "data/models" / (model + ".xml"));
    if (!xml) {
        state.SkipWithError(xml.error().to_string().c_str());
        return;
    }
    const std::vector<FitInput> sets = fit_sets(xml->primitives);
    double root_volume = 0.0, pair_volume = 0.0;
    for (auto _ : state) {
        root_volume = 0.0;  // both sums are one pass's: the counters report volumes, not iteration counts
        pair_volume = 0.0;
        for (std::size_t s = 0; s < sets.size(); ++s) {
            const Obb box = covariance_only ? fit_obb_covariance(sets[s].spheres)
                                            : fit_obb(sets[s].spheres, sets[s].hint_axes);
            (s == 0 ? root_volume : pair_volume) += box.volume();
        }
        benchmark::DoNotOptimize(pair_volume);
    }
    state.counters["root_volume"] = root_volume;
    state.counters["pairs_volume"] = pair_volume;
    state.counters["fits"] = static_cast<double>(sets.size());
}

void register_fit_benchmarks() {
    for (const char* model : {"chair", "helicopter", "cannon", "tie_interceptor"}) {
        benchmark::RegisterBenchmark((std::string("FitObb/covariance/") + model).c_str(), fit_obb_on_model, model, true)
            ->Unit(benchmark::kMicrosecond);
        benchmark::RegisterBenchmark((std::string("FitObb/best/") + model).c_str(), fit_obb_on_model, model, false)
            ->Unit(benchmark::kMicrosecond);
    }
}

const bool fit_benchmarks_registered = (register_fit_benchmarks(), true);

}  // namespace
}  // namespace hbvh
