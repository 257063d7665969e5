// SPDX-License-Identifier: MIT
// Seeded random primitive sets, for tests and benchmarks of any size.
#pragma once

#include <cstdint>
#include <vector>

#include "hbvh/geometry/primitive.hpp"

namespace hbvh {

struct SceneOptions {
    std::uint32_t count = 16;          ///< Number of primitives.
    std::uint64_t seed = 1;
    double extent = 0.0;               ///< Side of the cube they are scattered in; 0 picks one that keeps density constant.
    double min_size = 0.2;             ///< Smallest primitive half size / radius.
    double max_size = 1.0;             ///< Largest.
    bool clustered = true;             ///< Scatter in clusters (like parts of objects) rather than uniformly.
};

/// A deterministic mix of OBBs, AABBs, spheres and capsules (same options, same scene, on any platform:
/// it uses its own splitmix64 generator, not the standard distributions).
[[nodiscard]] std::vector<Primitive> generate_scene(const SceneOptions& options);

/// Random rigid motion with translation in [-translation_range, translation_range]^3, from `seed`.
[[nodiscard]] RigidTransform random_transform(std::uint64_t seed, double translation_range);

/// The small deterministic generator behind generate_scene, for tests that need more draws.
class SplitMix64 {
public:
    explicit SplitMix64(std::uint64_t seed) : state_(seed) {}
    std::uint64_t next() {
        std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
        return z ^ (z >> 31);
    }
    /// Uniform in [0, 1).
    double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
    /// Uniform in [0, n).
    std::uint64_t below(std::uint64_t n) { return next() % n; }
    /// A uniformly random rotation (from a uniform unit quaternion, Shoemake's method).
    Mat3 rotation();

private:
    std::uint64_t state_;
};

}  // namespace hbvh
