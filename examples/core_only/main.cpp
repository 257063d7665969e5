// SPDX-License-Identifier: MIT
// hbvh::core alone: a hierarchy over primitives made in code, collided with a moved copy of itself; then stored
// as .hbvh and loaded straight into the query layout, as a program that ships prebuilt trees does at start-up.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <unistd.h>

#include <hbvh/builders/build.hpp>
#include <hbvh/query/tandem_traversal.hpp>
#include <hbvh/tree/binary_format.hpp>
#include <hbvh/tree/stats.hpp>
#include <hbvh/tree/validate.hpp>

namespace {

// Four unit-diameter spheres 2 apart along x, a capsule along x at y = 3 and a box at y = -3. Shifted by 0.8 along
// x, each primitive overlaps its own copy only (sphere centres 0.8 apart < 1; neighbours 1.2 apart > 1; the rows
// are 3 apart), so the pairs are (i, i) for every i.
std::vector<hbvh::Primitive> make_object() {
    std::vector<hbvh::Primitive> primitives;
    for (int i = 0; i < 4; ++i) {
        primitives.push_back({hbvh::Sphere{hbvh::Vec3(2.0 * i, 0.0, 0.0), 0.5}, "ball"});
    }
    primitives.push_back({hbvh::Capsule{hbvh::Vec3(0.0, 3.0, 0.0), hbvh::Vec3(6.0, 3.0, 0.0), 0.25}, "rail"});
    primitives.push_back(
        {hbvh::Obb{hbvh::Vec3(3.0, -3.0, 0.0), hbvh::Mat3::Identity(), hbvh::Vec3(1.0, 0.5, 0.5)}, "crate"});
    return primitives;
}

void print_pairs(const char* label, const hbvh::CollideResult& hit) {
    std::printf("%s %zu", label, hit.pairs.size());
    for (const auto& [a, b] : hit.pairs) std::printf(" %u-%u", a, b);
    std::printf("\n");
}

}  // namespace

int main() {
    const std::vector<hbvh::Primitive> primitives = make_object();
    auto bvh = hbvh::build(primitives, hbvh::Algorithm::automatic);
    if (!bvh) {
        std::fprintf(stderr, "%s\n", bvh.error().to_string().c_str());
        return 1;
    }
    if (const auto valid = hbvh::validate(*bvh); !valid) {
        std::fprintf(stderr, "%s\n", valid.error().to_string().c_str());
        return 1;
    }
    const hbvh::QueryTree tree(*bvh);
    const auto shifted = hbvh::RigidTransform::from_quaternion(1.0, 0.0, 0.0, 0.0, hbvh::Vec3(0.8, 0.0, 0.0));
    const auto apart = hbvh::RigidTransform::from_quaternion(1.0, 0.0, 0.0, 0.0, hbvh::Vec3(0.0, 0.0, 5.0));
    print_pairs("shifted", hbvh::collide(tree, hbvh::RigidTransform::identity(), tree, shifted));
    print_pairs("apart", hbvh::collide(tree, hbvh::RigidTransform::identity(), tree, apart));

    const std::filesystem::path stored =
        std::filesystem::temp_directory_path() / ("hbvh_core_only_" + std::to_string(::getpid()) + ".hbvh");
    if (const auto written = hbvh::write_binary_file(stored, *bvh); !written) {
        std::fprintf(stderr, "%s\n", written.error().to_string().c_str());
        return 1;
    }
    auto loaded = hbvh::QueryTree::read_binary_file(stored);
    std::filesystem::remove(stored);
    if (!loaded) {
        std::fprintf(stderr, "%s\n", loaded.error().to_string().c_str());
        return 1;
    }
    print_pairs("loaded", hbvh::collide(*loaded, hbvh::RigidTransform::identity(), *loaded, shifted));
    std::printf("nodes %zu cost %.6g\n", bvh->nodes.size(), hbvh::cost(*bvh));
}
