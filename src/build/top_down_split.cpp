// SPDX-License-Identifier: MIT
// Müller, Schäfer and Straßer's top-down splitting (survey §2.2): sort, sweep every cut point, recurse.
#include "hbvh/build/top_down_split.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>

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
        double best = std::numeric_limits<double>::infinity();
        const auto consider = [&](BvType type, double v) {
            if (policy_.is_allowed(type)) best = std::min(best, policy_.weight_of(type) * v);
        };
        consider(BvType::aabb, box_.volume());
        consider(BvType::obb, frame_box_.volume());
        consider(BvType::sphere, sphere_.volume());
        const double r = capsule_radius_;
        consider(BvType::capsule, std::numbers::pi * r * r * (t_max_ - t_min_) + 4.0 / 3.0 * std::numbers::pi * r * r * r);
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

class Splitter {
public:
    Splitter(const PrimitiveSet& set, TreeAssembler& assembler, const SplitOptions& options)
        : set_(set), assembler_(assembler), options_(options) {}

    // Builds the subtree over `locals` and returns its assembler id.
    std::uint32_t build(std::vector<std::uint32_t> locals) {
        if (locals.size() == 1) return assembler_.add_leaf(set_.input_index(locals.front()));
        const BoundingVolume volume = set_.fit(locals);
        const std::size_t cut = choose_cut(locals);  // locals is left sorted along the chosen axis
        std::vector<std::uint32_t> right(locals.begin() + static_cast<std::ptrdiff_t>(cut), locals.end());
        locals.resize(cut);
        const std::uint32_t children[2] = {build(std::move(locals)), build(std::move(right))};
        return assembler_.add_group(children, volume);
    }

private:
    // Sorts `locals` along the best axis and returns the size of the left part (1..size-1).
    std::size_t choose_cut(std::vector<std::uint32_t>& locals) {
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
        int best_axis = 0;
        std::size_t best_cut = count / 2;
        std::vector<double> prefix(count), suffix(count);
        for (int axis = 0; axis < 3; ++axis) {
            sort_along(locals, axis);
            side_volumes(locals, per_side, frame, prefix, suffix);
            for (std::size_t left = 1; left < count; ++left) {
                const double cost = static_cast<double>(left) * prefix[left - 1] +
                                    static_cast<double>(count - left) * suffix[left];
                // Strict '<': on equal cost the earlier axis and the earlier cut win, both fixed by geometry.
                if (cost < best_cost) {
                    best_cost = cost;
                    best_axis = axis;
                    best_cut = left;
                }
            }
        }
        sort_along(locals, best_axis);
        return best_cut;
    }

    // Centre along `axis`; equal centres fall back to the canonical index, itself an order on geometry.
    void sort_along(std::vector<std::uint32_t>& locals, int axis) const {
        std::sort(locals.begin(), locals.end(), [&](std::uint32_t a, std::uint32_t b) {
            const double ca = set_.centre(a)[axis], cb = set_.centre(b)[axis];
            return ca != cb ? ca < cb : a < b;
        });
    }

    // prefix[i]: weighted volume around locals[0..i]; suffix[i]: around locals[i..end).
    void side_volumes(const std::vector<std::uint32_t>& locals, bool per_side, const Obb& frame,
                      std::vector<double>& prefix, std::vector<double>& suffix) const {
        const std::size_t count = locals.size();
        if (per_side) {
            for (std::size_t i = 0; i < count; ++i) {
                prefix[i] = set_.estimate(std::span(locals).first(i + 1));
                suffix[i] = set_.estimate(std::span(locals).subspan(i));
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
    TreeAssembler& assembler_;
    const SplitOptions& options_;
};

}  // namespace

Result<Bvh> build_top_down_split(std::span<const Primitive> primitives, const VolumePolicy& policy,
                                 const SplitOptions& options) {
    if (primitives.empty()) return Error{"no primitives to build a hierarchy over"};
    const PrimitiveSet set(primitives, detail::canonical_order(primitives), policy);
    TreeAssembler assembler(primitives);
    std::vector<std::uint32_t> all(set.size());
    std::iota(all.begin(), all.end(), 0u);
    const std::uint32_t root = Splitter(set, assembler, options).build(std::move(all));
    return std::move(assembler).finish(root);
}

}  // namespace hbvh
