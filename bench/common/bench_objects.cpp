// SPDX-License-Identifier: MIT
#include "bench_objects.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <filesystem>

#include "hbvh/io/import.hpp"
#include "hbvh/io/xml.hpp"
#include "hbvh/scene/generate.hpp"

namespace hbvh::bench {
namespace {

std::vector<std::filesystem::path> files_in(const std::filesystem::path& folder, std::initializer_list<const char*> extensions) {
    std::vector<std::filesystem::path> files;
    if (!std::filesystem::is_directory(folder)) return files;
    for (const auto& entry : std::filesystem::directory_iterator(folder))
        if (std::find(extensions.begin(), extensions.end(), entry.path().extension().string()) != extensions.end())
            files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    return files;
}

}  // namespace

std::vector<BenchObject> load_bench_objects(const std::string& program) {
    std::vector<BenchObject> objects;
    for (const auto& file : files_in(HBVH_SOURCE_DIR "/data/models", {".xml"})) {
        Result<XmlModel> model = read_xml_file(file);
        if (!model) {
            fmt::print(stderr, "{}: skipping {}\n", program, model.error().to_string());
            continue;
        }
        objects.push_back({file.stem().string(), std::move(model->primitives)});
    }
    // Real MJCF and URDF models made by others; their mesh geoms are skipped by the importers, their
    // primitives kept.
    for (const auto& file : files_in(HBVH_SOURCE_DIR "/../shared/data/models", {".xml", ".urdf"})) {
        Result<ImportResult> imported = import_primitives(file.string());
        if (!imported || imported->primitives.size() < 2) {
            fmt::print(stderr, "{}: skipping {}\n", program,
                       imported ? file.string() + ": fewer than 2 primitives" : imported.error().to_string());
            continue;
        }
        objects.push_back({file.stem().string(), std::move(imported->primitives)});
    }
    for (std::uint32_t count : {13u, 27u, 100u, 1000u})
        objects.push_back({fmt::format("generated-{}", count), generate_scene({.count = count, .seed = 2024})});
    return objects;
}

}  // namespace hbvh::bench
