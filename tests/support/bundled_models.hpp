// SPDX-License-Identifier: MIT
// The bundled models (data/models/*.xml) as primitive sets, for the tests that run builders on real models.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "hbvh/io/xml.hpp"

namespace hbvh::test_support {

/// (file stem, primitives) of every data/models/*.xml, sorted by name. They ship with the repository, so a
/// missing folder, an empty one or an unreadable file fails the calling test instead of skipping it.
inline std::vector<std::pair<std::string, std::vector<Primitive>>> bundled_models() {
    std::vector<std::pair<std::string, std::vector<Primitive>>> models;
    const std::filesystem::path folder = std::filesystem::path(HBVH_SOURCE_DIR) / "data" / "models";
    if (!std::filesystem::is_directory(folder)) {
        ADD_FAILURE() << "missing bundled models: " << folder;
        return models;
    }
    for (const auto& entry : std::filesystem::directory_iterator(folder)) {
        if (entry.path().extension() != ".xml") continue;
        Result<XmlModel> model = read_xml_file(entry.path());
        if (!model.has_value()) {
            ADD_FAILURE() << entry.path() << ": " << model.error().to_string();
            continue;
        }
        models.emplace_back(entry.path().stem().string(), std::move(model->primitives));
    }
    std::sort(models.begin(), models.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    EXPECT_FALSE(models.empty()) << "no *.xml in " << folder;
    return models;
}

}  // namespace hbvh::test_support
