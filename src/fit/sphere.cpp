// SPDX-License-Identifier: MIT
// fit_sphere: the exact minimum enclosing sphere of spheres (and its 2-D twin for capsules), via CGAL.
#include <algorithm>

#include <CGAL/Min_sphere_of_spheres_d.h>
#include <CGAL/Min_sphere_of_spheres_d_traits_2.h>
#include <CGAL/Min_sphere_of_spheres_d_traits_3.h>
#include <CGAL/Simple_cartesian.h>

#include "hbvh/assert.hpp"
#include "hbvh/fit/fit.hpp"
#include "min_circle.hpp"
#include "rounding_pad.hpp"

namespace hbvh {
namespace {

// CGAL's Min_sphere_of_spheres_d (Fischer & Gärtner's algorithm) is exact for spheres of differing radii,
// unlike Welzl-style point algorithms. The default traits (no square-root field, farthest-first heuristic)
// work in plain double, which is all the result is stored in anyway.
using Kernel = CGAL::Simple_cartesian<double>;
using Traits3 = CGAL::Min_sphere_of_spheres_d_traits_3<Kernel, double>;
using Traits2 = CGAL::Min_sphere_of_spheres_d_traits_2<Kernel, double>;

/// Runs `solve` on an empty solver of these traits. Sets of up to kept_solver_size spheres get this thread's own
/// solver, cleared: a fresh one allocated its two arrays and their growth on every fit (a fifth of auto's
/// allocations, heaptrack on the ANYmal), a cleared one keeps their capacity. Clearing leaves nothing of the last
/// solve that the next reads: with these inexact traits the farthest-first heuristic runs alone, never the
/// randomised LP step whose generator would carry over, so the same spheres give the same ball. Larger sets get a
/// fresh solver, so that no thread keeps a large one (memory/thread_scratch.hpp).
constexpr std::size_t kept_solver_size = 4096;

template <class Traits, class Solve>
auto with_empty_solver(std::size_t count, Solve solve) {
    if (count > kept_solver_size) {
        CGAL::Min_sphere_of_spheres_d<Traits> fresh;
        return solve(fresh);
    }
    thread_local CGAL::Min_sphere_of_spheres_d<Traits> kept;
    kept.clear();
    return solve(kept);
}

}  // namespace

Sphere fit_sphere(std::span<const Sphere> spheres) {
    HBVH_ASSERT(!spheres.empty());
    // CGAL works on squares of squared distances, which overflow for spans beyond ~1e75 (a sphere at 1e150
    // came back with a NaN centre): solve for the set moved to the origin and scaled to unit size, then undo.
    Vec3 low = spheres.front().center, high = low;
    double largest_radius = 0.0;
    for (const Sphere& s : spheres) {
        low = low.cwiseMin(s.center);
        high = high.cwiseMax(s.center);
        largest_radius = std::max(largest_radius, s.radius);
    }
    const Vec3 origin = 0.5 * (low + high);
    const double span = std::max((high - low).maxCoeff(), largest_radius);
    const double scale = span > 0.0 ? span : 1.0;
    Sphere result = with_empty_solver<Traits3>(spheres.size(), [&](CGAL::Min_sphere_of_spheres_d<Traits3>& solver) {
        for (const Sphere& s : spheres) {
            const Vec3 c = (s.center - origin) / scale;
            solver.insert(Traits3::Sphere(Kernel::Point_3(c.x(), c.y(), c.z()), s.radius / scale));
        }
        Sphere ball;
        auto coordinate = solver.center_cartesian_begin();
        for (int k = 0; k < 3; ++k, ++coordinate) ball.center[k] = *coordinate * scale + origin[k];
        ball.radius = solver.radius() * scale;
        return ball;
    });
    // CGAL's answer is optimal up to rounding; measure containment the way Sphere::contains does and grow.
    for (const Sphere& s : spheres) result.radius = std::max(result.radius, (s.center - result.center).norm() + s.radius);
    // The distances are of nearby points, so their rounding scales with the radius, not the coordinates.
    result.radius += detail::rounding_pad(result.radius);
    return result;
}

namespace detail {

Circle min_circle_of_circles(std::span<const Circle> circles) {
    HBVH_ASSERT(!circles.empty());
    Circle result = with_empty_solver<Traits2>(circles.size(), [&](CGAL::Min_sphere_of_spheres_d<Traits2>& solver) {
        for (const Circle& c : circles) solver.insert(Traits2::Sphere(Kernel::Point_2(c.center.x(), c.center.y()), c.radius));
        Circle circle;
        auto coordinate = solver.center_cartesian_begin();
        circle.center.x() = *coordinate;
        ++coordinate;
        circle.center.y() = *coordinate;
        circle.radius = solver.radius();
        return circle;
    });
    for (const Circle& c : circles) result.radius = std::max(result.radius, (c.center - result.center).norm() + c.radius);
    return result;
}

}  // namespace detail
}  // namespace hbvh
