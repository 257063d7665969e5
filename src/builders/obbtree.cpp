// SPDX-License-Identifier: MIT
// Gottschalk, Lin and Manocha's OBB-tree construction (SIGGRAPH 1996; survey §2.2).
#include "hbvh/builders/obbtree.hpp"

#include <algorithm>
#include <array>
#include <numeric>

#include "guarded_build.hpp"
#include "heuristic_support.hpp"
#include "hbvh/fit/fit.hpp"

namespace hbvh {
namespace {

using detail::PrimitiveSet;

class ObbTreeBuilder {
public:
    ObbTreeBuilder(const PrimitiveSet& set, TreeAssembler& assembler, const ObbTreeOptions& options,
                   const detail::Checkpoint& checkpoint)
        : set_(set), assembler_(assembler), options_(options), checkpoint_(checkpoint) {}

    std::uint32_t build(std::vector<std::uint32_t> locals) {
        if (locals.size() == 1) {
            ++placed_;
            return assembler_.add_leaf(set_.input_index(locals.front()));
        }
        checkpoint_.step(static_cast<double>(placed_));
        // Summing in canonical order keeps the covariance, and so every later decision, bitwise
        // independent of the input order.
        std::sort(locals.begin(), locals.end());
        std::vector<Sphere> spheres;
        for (const std::uint32_t local : locals) {
            const auto own = set_.spheres(local);
            spheres.insert(spheres.end(), own.begin(), own.end());
        }
        const Obb box = fit_obb_covariance(spheres);
        const BoundingVolume volume = options_.covariance_obb_volumes ? BoundingVolume{box} : set_.fit(locals);

        std::vector<std::uint32_t> left, right;
        split(locals, box, left, right);
        const std::uint32_t children[2] = {build(std::move(left)), build(std::move(right))};
        return assembler_.add_group(children, volume);
    }

private:
    void split(const std::vector<std::uint32_t>& locals, const Obb& box, std::vector<std::uint32_t>& left,
               std::vector<std::uint32_t>& right) const {
        // Axes longest first; equal extents keep the frame's own order.
        std::array<int, 3> axes{0, 1, 2};
        std::stable_sort(axes.begin(), axes.end(),
                         [&](int a, int b) { return box.half_extents[a] > box.half_extents[b]; });
        for (const int axis : axes) {
            const Vec3 direction = box.rotation.col(axis);
            // The survey's "mean point": the mean of the primitives' centres (Gottschalk averages triangle
            // centroids; our primitives are the artist's volumes, so their centres play that role).
            double mean = 0.0;
            for (const std::uint32_t local : locals) mean += direction.dot(set_.centre(local));
            mean /= static_cast<double>(locals.size());
            left.clear();
            right.clear();
            for (const std::uint32_t local : locals)
                (direction.dot(set_.centre(local)) < mean ? left : right).push_back(local);
            if (!left.empty() && !right.empty()) return;
        }
        // Every axis put all centres on one side (coincident centres): cut at the median of the longest
        // axis, ties broken by the canonical index so the halves depend on geometry only.
        const Vec3 direction = box.rotation.col(axes[0]);
        std::vector<std::uint32_t> sorted = locals;
        std::sort(sorted.begin(), sorted.end(), [&](std::uint32_t a, std::uint32_t b) {
            const double pa = direction.dot(set_.centre(a)), pb = direction.dot(set_.centre(b));
            return pa != pb ? pa < pb : a < b;
        });
        const auto middle = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
        left.assign(sorted.begin(), middle);
        right.assign(middle, sorted.end());
    }

    const PrimitiveSet& set_;
    TreeAssembler& assembler_;
    const ObbTreeOptions& options_;
    const detail::Checkpoint& checkpoint_;
    std::uint32_t placed_ = 0;  ///< Leaves added so far, for progress.
};

}  // namespace

Result<Bvh> build_obbtree(std::span<const Primitive> primitives, const BuildContext& context,
                          const ObbTreeOptions& options) {
    return detail::guarded_build(primitives, context, "obbtree", static_cast<double>(primitives.size()),
                                 [&](const detail::Checkpoint& checkpoint) {
                                     const PrimitiveSet set(primitives, detail::canonical_order(primitives), context.policy);
                                     TreeAssembler assembler(primitives);
                                     std::vector<std::uint32_t> all(set.size());
                                     std::iota(all.begin(), all.end(), 0u);
                                     const std::uint32_t root =
                                         ObbTreeBuilder(set, assembler, options, checkpoint).build(std::move(all));
                                     return std::move(assembler).finish(root);
                                 });
}

}  // namespace hbvh
