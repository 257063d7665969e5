// SPDX-License-Identifier: MIT
// The README's library example as a program: build a hierarchy over a survey XML file and collide it with itself.
#include <hbvh/hbvh.hpp>
#include <cstdio>
int main(int argc, char** argv) {
    if (argc != 2) { std::fprintf(stderr, "usage: %s MODEL.xml\n", argv[0]); return 2; }  // (not in issue 12's text)
    auto model = hbvh::read_xml_file(argv[1]);            // survey XML primitive set
    if (!model) { std::fprintf(stderr, "%s\n", model.error().to_string().c_str()); return 1; }
    auto bvh = hbvh::build(model->primitives, hbvh::Algorithm::automatic);
    if (!bvh) { std::fprintf(stderr, "%s\n", bvh.error().to_string().c_str()); return 1; }
    const hbvh::QueryTree tree(*bvh);
    const auto pose = hbvh::RigidTransform::from_quaternion(0.92, 0.0, 0.38, 0.0, hbvh::Vec3(0.3, 0.0, 0.0));
    const hbvh::CollideResult hit = hbvh::collide(tree, hbvh::RigidTransform::identity(), tree, pose);
    std::printf("%d %zu %.9g\n", hit.intersecting ? 1 : 0, hit.pairs.size(), hbvh::cost(*bvh));
}
