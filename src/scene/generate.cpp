// SPDX-License-Identifier: MIT
#include "hbvh/scene/generate.hpp"

#include <cmath>
#include <numbers>
#include <string>

namespace hbvh {

Mat3 SplitMix64::rotation() {
    // Shoemake (1992): three uniforms give a uniform unit quaternion.
    const double u1 = uniform(), u2 = uniform(), u3 = uniform();
    const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
    const double t2 = 2.0 * std::numbers::pi * u2, t3 = 2.0 * std::numbers::pi * u3;
    const Eigen::Quaterniond q(b * std::cos(t3), a * std::sin(t2), a * std::cos(t2), b * std::sin(t3));
    return q.normalized().toRotationMatrix();
}

std::vector<Primitive> generate_scene(const SceneOptions& options) {
    SplitMix64 rng(options.seed);
    // Keep the number density constant so that large scenes look like many small objects side by side.
    const double extent = options.extent > 0.0 ? options.extent
                                               : 4.0 * options.max_size * std::cbrt(static_cast<double>(options.count));
    std::vector<Vec3> cluster_centers;
    if (options.clustered) {
        const std::uint32_t clusters = std::max<std::uint32_t>(1, options.count / 6);
        for (std::uint32_t c = 0; c < clusters; ++c)
            cluster_centers.emplace_back(rng.uniform(0, extent), rng.uniform(0, extent), rng.uniform(0, extent));
    }
    std::vector<Primitive> primitives;
    primitives.reserve(options.count);
    for (std::uint32_t i = 0; i < options.count; ++i) {
        Vec3 center(rng.uniform(0, extent), rng.uniform(0, extent), rng.uniform(0, extent));
        if (options.clustered) {
            const Vec3& cluster = cluster_centers[rng.below(cluster_centers.size())];
            const double spread = 3.0 * options.max_size;
            center = cluster + Vec3(rng.uniform(-spread, spread), rng.uniform(-spread, spread), rng.uniform(-spread, spread));
        }
        const auto size = [&] { return rng.uniform(options.min_size, options.max_size); };
        Primitive p;
        p.name = "p" + std::to_string(i);
        switch (rng.below(4)) {
            case 0: p.volume = Obb{center, rng.rotation(), Vec3(size(), size(), size())}; break;
            case 1: {
                const Vec3 half(size(), size(), size());
                p.volume = Aabb{center - half, center + half};
                break;
            }
            case 2: p.volume = Sphere{center, size()}; break;
            default: {
                const Vec3 axis = rng.rotation().col(2) * size();
                p.volume = Capsule{center - axis, center + axis, 0.5 * size()};
                break;
            }
        }
        primitives.push_back(std::move(p));
    }
    return primitives;
}

RigidTransform random_transform(std::uint64_t seed, double translation_range) {
    SplitMix64 rng(seed);
    RigidTransform t;
    t.rotation = rng.rotation();
    t.translation = Vec3(rng.uniform(-translation_range, translation_range), rng.uniform(-translation_range, translation_range),
                         rng.uniform(-translation_range, translation_range));
    return t;
}

}  // namespace hbvh
