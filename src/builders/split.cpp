// SPDX-License-Identifier: MIT
// Müller, Schäfer and Straßer's top-down splitting (survey §2.2): sort, sweep every cut point, recurse.
#include "hbvh/builders/split.hpp"

#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <span>
#include <vector>

#include "guarded_build.hpp"
#include "heuristic_support.hpp"
#include "hbvh/fit/fit.hpp"

namespace hbvh {
namespace {

using detail::PrimitiveSet;

// Running estimates of the smallest BV of each kind around a growing prefix of primitives. Each is a
// real enclosing BV (so an upper bound of what fit_best would find) and costs O(1) per added sphere,
// which keeps a sweep over n cut points linear instead of n fits (survey §2.2 gives no BV model).
class RunningVolume {
public:
    RunningVolume(const VolumePolicy& policy, const Obb& frame) : policy_(policy), frame_(frame) {
        frame_.half_extents.maxCoeff(&main_axis_);
    }

    void add(const Sphere& s) {
        const Vec3 r = Vec3::Constant(s.radius);
        box_ = box_.merged({s.center - r, s.center + r});
        const Vec3 local = frame_.rotation.transpose() * (s.center - frame_.center);
        frame_box_ = frame_box_.merged({local - r, local + r});
        grow_sphere(s);
        const double t = local[main_axis_];
        Vec3 perpendicular = local;
        perpendicular[main_axis_] = 0.0;
        capsule_radius_ = std::max(capsule_radius_, perpendicular.norm() + s.radius);
        t_min_ = std::min(t_min_, t);
        t_max_ = std::max(t_max_, t);
    }

    // Smallest weighted volume among the allowed kinds.
    [[nodiscard]] double weighted_volume() const {
        // Each candidate is measured as the policy measures a node (volume, or the calibrated objective's
        // measure); both are rotation-invariant, so the box in the frame stands for the OBB and a capsule along
        // z for the one along the frame's main axis.
        double best = std::numeric_limits<double>::infinity();
        const auto consider = [&](BvType type, const BoundingVolume& candidate) {
            if (!policy_.is_allowed(type)) return;
            best = std::min(best, policy_.weight_of(type) * policy_.unweighted_measure(candidate));
        };
        consider(BvType::aabb, box_);
        consider(BvType::obb, frame_box_);
        consider(BvType::sphere, sphere_);
        consider(BvType::capsule, Capsule{Vec3(0, 0, t_min_), Vec3(0, 0, t_max_), capsule_radius_});
        return best;
    }

private:
    // Ritter-style growth: the smallest sphere around the current sphere and the new one.
    void grow_sphere(const Sphere& s) {
        if (!has_sphere_) {
            sphere_ = s;
            has_sphere_ = true;
            return;
        }
        const Vec3 d = s.center - sphere_.center;
        const double distance = d.norm();
        if (distance + s.radius <= sphere_.radius) return;
        if (distance + sphere_.radius <= s.radius) {
            sphere_ = s;
            return;
        }
        const double radius = 0.5 * (distance + sphere_.radius + s.radius);
        sphere_.center += ((radius - sphere_.radius) / distance) * d;
        sphere_.radius = radius;
    }

    const VolumePolicy& policy_;
    Obb frame_;
    Eigen::Index main_axis_ = 0;
    Aabb box_ = Aabb::empty();
    Aabb frame_box_ = Aabb::empty();
    Sphere sphere_;
    bool has_sphere_ = false;
    double capsule_radius_ = 0.0;
    double t_min_ = std::numeric_limits<double>::infinity();
    double t_max_ = -std::numeric_limits<double>::infinity();
};

/// One node of the split tree before assembly: a leaf (one primitive) or an inner node with two children
/// (indices into the same plan) and its BV.
struct PlannedNode {
    bool is_leaf = false;
    std::uint32_t local = 0;  ///< Leaves: the primitive.
    std::uint32_t left = 0;   ///< Inner nodes: children's plan indices.
    std::uint32_t right = 0;
    BoundingVolume volume;
};

/// Plans the tree top-down, the two halves of every cut in parallel (TBB), then hands it to the assembler
/// in the order a serial recursion would. A node's plan slot is fixed by its range of the primitive order,
/// not by which thread made it, and each range's sorting and fitting read only that range, so the tree is
/// the same for any thread count.
class Splitter {
public:
    Splitter(const PrimitiveSet& set, const SplitOptions& options, const detail::Checkpoint& checkpoint)
        : set_(set), options_(options), checkpoint_(checkpoint), order_(set.size()), plan_(2 * set.size() - 1) {
        std::iota(order_.begin(), order_.end(), 0u);
    }

    /// The hierarchy's root id in `assembler` after adding every node.
    std::uint32_t build(TreeAssembler& assembler) {
        const std::uint32_t root = plan(0, static_cast<std::uint32_t>(order_.size()));
        return assemble(root, assembler);
    }

private:
    /// Slots: leaf of order position i at i; the inner node cutting its range before position c at n - 1 + c
    /// (every gap between consecutive positions is cut by exactly one inner node).
    std::uint32_t plan(std::uint32_t begin, std::uint32_t end) {
        if (end - begin == 1) {
            plan_[begin] = PlannedNode{true, order_[begin], 0, 0, {}};
            placed_.fetch_add(1, std::memory_order_relaxed);
            return begin;
        }
        checkpoint_.step(static_cast<double>(placed_.load(std::memory_order_relaxed)));
        const std::span<std::uint32_t> locals(order_.data() + begin, end - begin);
        BoundingVolume volume = set_.fit(locals);
        const auto cut = begin + static_cast<std::uint32_t>(choose_cut(locals));  // sorts locals along the chosen axis
        std::uint32_t left = 0;
        std::uint32_t right = 0;
        // Small ranges stay on this thread: a task costs more than they do.
        constexpr std::uint32_t parallel_above = 256;
        if (end - begin > parallel_above)
            tbb::parallel_invoke([&] { left = plan(begin, cut); }, [&] { right = plan(cut, end); });
        else
            left = plan(begin, cut), right = plan(cut, end);
        const auto slot = static_cast<std::uint32_t>(order_.size()) - 1 + cut;
        plan_[slot] = PlannedNode{false, 0, left, right, std::move(volume)};
        return slot;
    }

    /// Left subtree, right subtree, then the node: the order of the former serial recursion.
    std::uint32_t assemble(std::uint32_t slot, TreeAssembler& assembler) const {
        const PlannedNode& node = plan_[slot];
        if (node.is_leaf) return assembler.add_leaf(set_.input_index(node.local));
        const std::uint32_t children[2] = {assemble(node.left, assembler), assemble(node.right, assembler)};
        return assembler.add_group(children, node.volume);
    }

    // Sorts `locals` along the best axis and returns the size of the left part (1..size-1).
    std::size_t choose_cut(std::span<std::uint32_t> locals) const {
        const std::size_t count = locals.size();
        const bool per_side = count <= options_.per_side_pricing_limit;
        Obb frame;
        if (!per_side) {
            std::vector<Sphere> spheres;
            for (const std::uint32_t local : locals) {
                const auto own = set_.spheres(local);
                spheres.insert(spheres.end(), own.begin(), own.end());
            }
            frame = fit_obb_covariance(spheres);
        }
        double best_cost = std::numeric_limits<double>::infinity();
        std::size_t best_imbalance = count;
        int best_axis = 0;
        std::size_t best_cut = count / 2;
        std::vector<double> prefix(count), suffix(count);
        for (int axis = 0; axis < 3; ++axis) {
            sort_along(locals, axis);
            side_volumes(locals, per_side, frame, prefix, suffix);
            for (std::size_t left = 1; left < count; ++left) {
                const double cost = static_cast<double>(left) * prefix[left - 1] +
                                    static_cast<double>(count - left) * suffix[left];
                // On equal cost the more even cut wins, then the earlier axis and the earlier cut, all fixed by
                // geometry. Flat or point-like primitives cost 0 under any cut (a tiled floor), and taking the
                // first cut there peeled one primitive a level: a chain of height n - 1.
                const std::size_t imbalance = 2 * left > count ? 2 * left - count : count - 2 * left;
                if (cost < best_cost || (cost == best_cost && imbalance < best_imbalance)) {
                    best_cost = cost;
                    best_imbalance = imbalance;
                    best_axis = axis;
                    best_cut = left;
                }
            }
        }
        sort_along(locals, best_axis);
        return best_cut;
    }

    // Centre along `axis`; equal centres fall back to the canonical index, itself an order on geometry.
    void sort_along(std::span<std::uint32_t> locals, int axis) const {
        std::sort(locals.begin(), locals.end(), [&](std::uint32_t a, std::uint32_t b) {
            const double ca = set_.centre(a)[axis], cb = set_.centre(b)[axis];
            return ca != cb ? ca < cb : a < b;
        });
    }

    // prefix[i]: weighted volume around locals[0..i]; suffix[i]: around locals[i..end).
    void side_volumes(std::span<const std::uint32_t> locals, bool per_side, const Obb& frame,
                      std::vector<double>& prefix, std::vector<double>& suffix) const {
        const std::size_t count = locals.size();
        if (per_side) {
            for (std::size_t i = 0; i < count; ++i) {
                prefix[i] = set_.estimate(locals.first(i + 1));
                suffix[i] = set_.estimate(locals.subspan(i));
            }
            return;
        }
        RunningVolume forward(set_.policy(), frame), backward(set_.policy(), frame);
        for (std::size_t i = 0; i < count; ++i) {
            for (const Sphere& s : set_.spheres(locals[i])) forward.add(s);
            prefix[i] = forward.weighted_volume();
            for (const Sphere& s : set_.spheres(locals[count - 1 - i])) backward.add(s);
            suffix[count - 1 - i] = backward.weighted_volume();
        }
    }

    const PrimitiveSet& set_;
    const SplitOptions& options_;
    const detail::Checkpoint& checkpoint_;
    std::atomic<std::uint64_t> placed_{0};  ///< Leaves planned so far, for progress (any thread).
    std::vector<std::uint32_t> order_;  ///< Local primitive indices; each plan() call sorts only its range.
    std::vector<PlannedNode> plan_;     ///< n leaves, then n - 1 inner nodes by their cut position.
};

}  // namespace

Result<Bvh> build_split(std::span<const Primitive> primitives, const BuildContext& context,
                        const SplitOptions& options) {
    return detail::guarded_build(primitives, context, "split", static_cast<double>(primitives.size()),
                                 [&](const detail::Checkpoint& checkpoint) {
                                     const PrimitiveSet set(primitives, detail::canonical_order(primitives), context.policy);
                                     TreeAssembler assembler(primitives);
                                     const std::uint32_t root = Splitter(set, options, checkpoint).build(assembler);
                                     return std::move(assembler).finish(root);
                                 });
}

}  // namespace hbvh
