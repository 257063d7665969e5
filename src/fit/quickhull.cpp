// SPDX-License-Identifier: MIT
// Quickhull for the small sets the fitters see (tens to hundreds of sphere centres), written here because
// qhull's per-call set-up and allocations dominated those calls (docs/fitting.md, "Own hull"). Any doubt
// about rounding returns nothing, and summarize_hull then asks qhull.
#include "quickhull.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "../simd/wide_clones.hpp"

namespace hbvh::detail {
namespace {

constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();

/// One triangle of the growing hull. Edge k runs from vertex[k] to vertex[(k + 1) % 3].
struct Face {
    std::array<std::uint32_t, 3> vertex{};
    std::array<std::uint32_t, 3> neighbor{};  ///< The face across edge k.
    Vec3 normal = Vec3::Zero();               ///< Unit, outward.
    double offset = 0.0;                      ///< normal . x on the plane.
    std::uint32_t outside_head = none;        ///< First point of the outside set, linked through next_outside.
    std::uint32_t furthest = none;            ///< The outside point farthest above the plane.
    double furthest_distance = 0.0;
    bool alive = true;
    bool visible = false;  ///< Scratch of one step: in the region the current eye point sees.
};

/// One edge of the horizon: edge `edge` of the visible face `face`, whose neighbour across it is not visible.
struct HorizonEdge {
    std::uint32_t face;
    int edge;
};

/// The growing hull's arrays, kept from one call to the next on each thread (quickhull()).
struct QuickhullBuffers {
    std::vector<Face> faces;
    std::vector<std::uint32_t> next_outside;
    std::vector<std::uint32_t> pending;
    std::vector<std::uint32_t> visible;
    std::vector<HorizonEdge> horizon;
    std::vector<std::uint32_t> vertex_stamp;
    std::vector<std::uint32_t> new_faces;
    std::vector<std::uint32_t> output_index;
};

class Quickhull {
public:
    Quickhull(std::span<const Vec3> points, QuickhullBuffers& buffers)
        : points_(points), faces_(buffers.faces), next_outside_(buffers.next_outside), pending_(buffers.pending),
          visible_(buffers.visible), horizon_(buffers.horizon), vertex_stamp_(buffers.vertex_stamp),
          new_faces_(buffers.new_faces), output_index_(buffers.output_index) {
        faces_.clear();
        next_outside_.assign(points.size(), none);
        pending_.clear();
        visible_.clear();
        horizon_.clear();
        vertex_stamp_.assign(points.size(), 0);
        new_faces_.clear();
    }

    /// After run() returned nothing: whether that was because the points are flat beyond doubt.
    [[nodiscard]] bool flat_within_rounding() const { return flat_within_rounding_; }

    std::optional<TriangleHull> run() {
        if (points_.size() < 4) return std::nullopt;
        double scale = 0.0;
        for (const Vec3& p : points_) scale = std::max(scale, p.cwiseAbs().sum());
        // Rounding in a plane distance is a few ulps of the coordinates; points this close to a plane are
        // on it. The same threshold decides whether the points span a solid at all.
        tolerance_ = 1e-12 * scale;
        if (scale == 0.0) flat_within_rounding_ = true;  // every point the same
        if (!(tolerance_ > 0.0) || !std::isfinite(tolerance_)) return std::nullopt;
        if (!make_simplex()) return std::nullopt;
        while (!pending_.empty()) {
            const std::uint32_t f = pending_.back();
            pending_.pop_back();
            if (!faces_[f].alive || faces_[f].outside_head == none) continue;
            if (!add_point(f)) return std::nullopt;
        }
        return finish();
    }

private:
    [[nodiscard]] double distance(std::uint32_t face, std::uint32_t point) const {
        return faces_[face].normal.dot(points_[point]) - faces_[face].offset;
    }

    /// Appends the face (a, b, c); nothing when the triangle is a sliver whose normal rounding would decide.
    std::optional<std::uint32_t> add_face(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
        const Vec3 ab = points_[b] - points_[a];
        const Vec3 ac = points_[c] - points_[a];
        const Vec3 n = ab.cross(ac);
        const double squared_length = n.squaredNorm();
        // |ab x ac| = |ab| |ac| sin(angle), and n's direction is off by about eps / sin(angle): a point at the
        // set's scale is then misplaced by up to 2 eps scale / sin. Above 1e-5 that stays under 5e-11 of the
        // scale; thinner triangles (a cluster of nanometres beside a far point, found by fuzz_collide) go to qhull.
        // (Compared squared: one square root per face instead of three.)
        if (!(squared_length > 1e-10 * ab.squaredNorm() * ac.squaredNorm())) return std::nullopt;
        Face face;
        face.vertex = {a, b, c};
        face.normal = n / std::sqrt(squared_length);
        face.offset = face.normal.dot((points_[a] + points_[b] + points_[c]) / 3.0);
        faces_.push_back(face);
        return static_cast<std::uint32_t>(faces_.size() - 1);
    }

    /// Puts `point` into the first face of `candidates` it is outside of; false when it is outside none.
    bool assign(std::uint32_t point, std::span<const std::uint32_t> candidates) {
        for (std::uint32_t f : candidates) {
            const double d = distance(f, point);
            if (!(d > tolerance_)) continue;
            Face& face = faces_[f];
            next_outside_[point] = face.outside_head;
            face.outside_head = point;
            if (d > face.furthest_distance) face.furthest_distance = d, face.furthest = point;
            return true;
        }
        return false;
    }

    /// make_simplex's refusal of points whose extent across the plane (or line, or point) of the simplex so far is
    /// `across`, no more than the tolerance: noted as flat beyond doubt when it is within 1e-15 of the scale, about
    /// four units in the last place of the coordinates, where no program can find a solid (qhull found none in the
    /// 3 924 such sets of docs/fitting.md, "Flat sets without qhull").
    bool refuse_as_flat(double across) {
        flat_within_rounding_ = across <= 1e-3 * tolerance_;
        return false;
    }

    /// The first tetrahedron, from the extreme points; false when the points are flat within the tolerance.
    bool make_simplex() {
        std::array<std::uint32_t, 6> extreme{};
        for (std::uint32_t i = 0; i < points_.size(); ++i)
            for (int axis = 0; axis < 3; ++axis) {
                if (points_[i][axis] < points_[extreme[2 * axis]][axis]) extreme[2 * axis] = i;
                if (points_[i][axis] > points_[extreme[2 * axis + 1]][axis]) extreme[2 * axis + 1] = i;
            }
        std::uint32_t i0 = 0, i1 = 0;
        double widest = 0.0;
        for (std::uint32_t a : extreme)
            for (std::uint32_t b : extreme)
                if (const double d = (points_[a] - points_[b]).squaredNorm(); d > widest) widest = d, i0 = a, i1 = b;
        if (!(std::sqrt(widest) > tolerance_)) return refuse_as_flat(std::sqrt(widest));
        const Vec3 u = (points_[i1] - points_[i0]).normalized();
        std::uint32_t i2 = i0;
        double off_line = 0.0;
        for (std::uint32_t i = 0; i < points_.size(); ++i) {
            const Vec3 d = points_[i] - points_[i0];
            if (const double s = (d - d.dot(u) * u).norm(); s > off_line) off_line = s, i2 = i;
        }
        if (!(off_line > tolerance_)) return refuse_as_flat(off_line);
        const Vec3 u1 = points_[i1] - points_[i0];
        const Vec3 u2 = points_[i2] - points_[i0];
        const Vec3 n = u1.cross(u2).normalized();
        std::uint32_t i3 = i0;
        double off_plane = 0.0;
        for (std::uint32_t i = 0; i < points_.size(); ++i)
            if (const double s = std::abs(n.dot(points_[i] - points_[i0])); s > off_plane) off_plane = s, i3 = i;
        if (!(off_plane > tolerance_)) return refuse_as_flat(off_plane);

        // One orientation for the whole tetrahedron, from one determinant whose sign must be beyond rounding
        // (its error is a few eps |u1| |u2| |u3|); the faces then take their vertex order from it, so every
        // edge is shared by two faces running it in opposite directions. (Deciding each face on its own from a
        // determinant near rounding once turned two faces the same way: an unlinked edge, a crash.)
        const Vec3 u3 = points_[i3] - points_[i0];
        const double orientation = u1.cross(u2).dot(u3);
        if (!(std::abs(orientation) > 1e-9 * u1.norm() * u2.norm() * u3.norm())) return false;
        if (orientation < 0.0) std::swap(i1, i2);
        // With i3 above the plane (i0, i1, i2), these four run counter-clockwise seen from outside.
        const std::array<std::array<std::uint32_t, 3>, 4> simplex{{{i0, i2, i1}, {i0, i1, i3}, {i1, i2, i3}, {i0, i3, i2}}};
        for (const auto& [a, b, c] : simplex)
            if (!add_face(a, b, c)) return false;
        // Neighbours: the face holding the same edge the other way round.
        for (std::uint32_t f = 0; f < 4; ++f)
            for (int k = 0; k < 3; ++k) {
                const std::uint32_t a = faces_[f].vertex[static_cast<std::size_t>(k)];
                const std::uint32_t b = faces_[f].vertex[static_cast<std::size_t>((k + 1) % 3)];
                faces_[f].neighbor[static_cast<std::size_t>(k)] = none;
                for (std::uint32_t g = 0; g < 4; ++g)
                    if (g != f && edge_index(g, b, a) >= 0) faces_[f].neighbor[static_cast<std::size_t>(k)] = g;
                if (faces_[f].neighbor[static_cast<std::size_t>(k)] == none) return false;
            }
        const std::array<std::uint32_t, 4> simplex_faces{0, 1, 2, 3};
        for (std::uint32_t i = 0; i < points_.size(); ++i)
            if (i != i0 && i != i1 && i != i2 && i != i3) assign(i, simplex_faces);
        for (std::uint32_t f = 0; f < 4; ++f) pending_.push_back(f);
        return true;
    }

    /// k such that face f's edge k runs from a to b, or -1.
    [[nodiscard]] int edge_index(std::uint32_t f, std::uint32_t a, std::uint32_t b) const {
        const auto& v = faces_[f].vertex;
        for (int k = 0; k < 3; ++k)
            if (v[static_cast<std::size_t>(k)] == a && v[static_cast<std::size_t>((k + 1) % 3)] == b) return k;
        return -1;
    }

    /// Depth-first over the faces `eye` sees, from `face` entered across its edge `entry`; the horizon
    /// comes out as one counter-clockwise loop because every face's edges are walked in order from the
    /// one it was entered by.
    void find_horizon(std::uint32_t eye, std::uint32_t face, int entry) {
        faces_[face].visible = true;
        visible_.push_back(face);
        for (int step = 0; step < 3; ++step) {
            const int k = (entry + step) % 3;
            const std::uint32_t other = faces_[face].neighbor[static_cast<std::size_t>(k)];
            if (other == none || !faces_[other].alive) {
                linked_ = false;
                continue;
            }
            if (faces_[other].visible) continue;
            if (distance(other, eye) > tolerance_) {
                const std::uint32_t a = faces_[face].vertex[static_cast<std::size_t>(k)];
                const std::uint32_t b = faces_[face].vertex[static_cast<std::size_t>((k + 1) % 3)];
                const int back = edge_index(other, b, a);
                if (back < 0) {
                    linked_ = false;
                    continue;
                }
                find_horizon(eye, other, back);
            } else {
                horizon_.push_back({face, k});
            }
        }
    }

    /// Adds the farthest outside point of face `start` to the hull; false when rounding made the step
    /// inconsistent.
    bool add_point(std::uint32_t start) {
        const std::uint32_t eye = faces_[start].furthest;
        visible_.clear();
        horizon_.clear();
        find_horizon(eye, start, 0);
        if (!linked_) return false;
        // The horizon must be one simple loop: each edge ends where the next begins, no vertex twice.
        const auto tail = [&](const HorizonEdge& e) { return faces_[e.face].vertex[static_cast<std::size_t>(e.edge)]; };
        const auto head = [&](const HorizonEdge& e) {
            return faces_[e.face].vertex[static_cast<std::size_t>((e.edge + 1) % 3)];
        };
        if (horizon_.size() < 3) return false;
        // A vertex met twice is found by a stamp per point (one per step), not by sorting the loop.
        ++step_;
        for (std::size_t i = 0; i < horizon_.size(); ++i) {
            if (head(horizon_[i]) != tail(horizon_[(i + 1) % horizon_.size()])) return false;
            std::uint32_t& stamp = vertex_stamp_[tail(horizon_[i])];
            if (stamp == step_) return false;
            stamp = step_;
        }

        // The cone from the eye to the horizon.
        const std::uint32_t first_new = static_cast<std::uint32_t>(faces_.size());
        const std::uint32_t count = static_cast<std::uint32_t>(horizon_.size());
        for (std::uint32_t i = 0; i < count; ++i) {
            const HorizonEdge& e = horizon_[i];
            const std::uint32_t a = tail(e);
            const std::uint32_t b = head(e);
            const std::uint32_t outer = faces_[e.face].neighbor[static_cast<std::size_t>(e.edge)];
            const std::optional<std::uint32_t> added = add_face(a, b, eye);
            if (!added) return false;
            Face& face = faces_[*added];
            face.neighbor = {outer, first_new + (i + 1) % count, first_new + (i + count - 1) % count};
            const int back = edge_index(outer, b, a);
            if (back < 0) return false;
            faces_[outer].neighbor[static_cast<std::size_t>(back)] = *added;
        }
        // The visible faces' outside points go to the new faces they are outside of; the rest are inside now.
        new_faces_.clear();
        for (std::uint32_t f = first_new; f < faces_.size(); ++f) new_faces_.push_back(f);
        for (std::uint32_t f : visible_) {
            Face& face = faces_[f];
            face.alive = false;
            for (std::uint32_t p = face.outside_head; p != none;) {
                const std::uint32_t next = next_outside_[p];
                if (p != eye) assign(p, new_faces_);
                p = next;
            }
            face.outside_head = none;
        }
        for (std::uint32_t f : new_faces_) pending_.push_back(f);
        return true;
    }

    /// The live faces as a TriangleHull, after checking that they close up as a triangulated sphere.
    std::optional<TriangleHull> finish() {
        TriangleHull hull;
        std::vector<std::uint32_t>& output_index = output_index_;
        output_index.assign(faces_.size(), none);
        // Sized once: grown by push_back, these three arrays were about 25 allocations per call, a quarter of
        // all of auto's allocations (heaptrack on the ANYmal).
        const auto live = static_cast<std::size_t>(
            std::count_if(faces_.begin(), faces_.end(), [](const Face& face) { return face.alive; }));
        hull.triangles.reserve(live);
        hull.neighbors.reserve(live);
        hull.vertices.reserve(3 * live);
        for (std::uint32_t f = 0; f < faces_.size(); ++f) {
            if (!faces_[f].alive) continue;
            output_index[f] = static_cast<std::uint32_t>(hull.triangles.size());
            hull.triangles.push_back(faces_[f].vertex);
            for (std::uint32_t v : faces_[f].vertex) hull.vertices.push_back(v);
        }
        for (std::uint32_t f = 0; f < faces_.size(); ++f) {
            if (!faces_[f].alive) continue;
            std::array<std::uint32_t, 3> across{};
            for (std::size_t k = 0; k < 3; ++k) {
                across[k] = output_index[faces_[f].neighbor[k]];
                if (across[k] == none) return std::nullopt;  // linked to a deleted face
            }
            hull.neighbors.push_back(across);
        }
        // The corners ascending, each once: marked per point, then collected in index order (no sort).
        ++step_;
        for (const std::uint32_t v : hull.vertices) vertex_stamp_[v] = step_;
        hull.vertices.clear();
        for (std::uint32_t p = 0; p < points_.size(); ++p)
            if (vertex_stamp_[p] == step_) hull.vertices.push_back(p);
        // Euler's formula for a closed surface of triangles, V - E + F = 2 with E = 3F/2: F = 2V - 4.
        if (hull.triangles.size() != 2 * hull.vertices.size() - 4) return std::nullopt;
        return hull;
    }

    std::span<const Vec3> points_;
    double tolerance_ = 0.0;
    bool linked_ = true;  ///< Cleared when two neighbours disagree about their shared edge.
    bool flat_within_rounding_ = false;  ///< Refused because the points lie within rounding of a plane.
    std::vector<Face>& faces_;
    std::vector<std::uint32_t>& next_outside_;
    std::vector<std::uint32_t>& pending_;
    std::vector<std::uint32_t>& visible_;
    std::vector<HorizonEdge>& horizon_;
    std::vector<std::uint32_t>& vertex_stamp_;  ///< Per point: the last step_ that marked it.
    std::uint32_t step_ = 0;
    std::vector<std::uint32_t>& new_faces_;
    std::vector<std::uint32_t>& output_index_;
};

}  // namespace

// Compiled for AVX2 too, the steps inlined (simd/wide_clones.hpp), as are two other hot loops of a fit: the
// outlines and the face-flush frames (docs/fitting.md, "AVX2 copies").
HBVH_WIDE_CLONES_INLINED std::optional<TriangleHull> quickhull(std::span<const Vec3> points, bool* flat_within_rounding) {
    // Fresh arrays on every call grew into memory that the allocator had just returned to the kernel: half the
    // page faults of auto over the MuJoCo cards, and a tenth of its time (docs/fitting.md, "Own hull"). Kept per thread, they reach the
    // largest hull that thread has built (at most quickhull_max_points points) and stay there.
    thread_local QuickhullBuffers buffers;
    Quickhull hull(points, buffers);
    std::optional<TriangleHull> result = hull.run();
    if (flat_within_rounding != nullptr) *flat_within_rounding = !result && hull.flat_within_rounding();
    return result;
}

}  // namespace hbvh::detail
