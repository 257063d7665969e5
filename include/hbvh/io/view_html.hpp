// SPDX-License-Identifier: MIT
// A self-contained HTML viewer of a hierarchy's levels (no network: inline script, embedded geometry).
#pragma once

#include <string>
#include <string_view>

#include "hbvh/io/bv_mesh.hpp"
#include "hbvh/tree/bvh.hpp"

namespace hbvh {

/// Choices for export_html.
struct HtmlOptions {
    /// Tessellation of spheres and capsules; coarser than the glTF default because the page draws with
    /// the 2D canvas, where each triangle costs a path fill.
    MeshDetail detail{16, 8};
    /// Above this many nodes curved surfaces use 8 segments x 4 rings instead, so that large scenes
    /// still rotate smoothly (a 2D canvas fills some 10^5 triangles per second on a slow machine).
    std::size_t coarse_above_nodes = 300;
};

/// One HTML page that draws the object and the BVs of one level at a time (a slider picks the level,
/// drag rotates, the wheel zooms, the arrow keys step through levels). The initial level comes from
/// the URL hash "#level=N" (default 0; clamped to the deepest level) and the slider keeps the hash up
/// to date; "#all" draws every level at once in a grid of labelled tiles (the survey's Figures 14-15),
/// without the panel. Each level shows its nodes translucent in level_color(depth), the primitives inside them in
/// solid grey, and carried leaves in carried_color() (see LevelView), with per-level statistics: nodes
/// on the level, carried leaves, sum of volumes, the level's share of the Eq. 2 cost, types used.
///
/// The renderer is a small painter's-algorithm rasteriser on a 2D canvas written into the page, so the
/// page works offline and without WebGL. The geometry (triangulate() meshes, coordinates quantised to
/// 2^-20 of the model's size) and the statistics are embedded as JSON in
/// <script type="application/json" id="hbvh-data">. `title` is shown as the page title and heading.
[[nodiscard]] std::string export_html(const Bvh& bvh, std::string_view title, const HtmlOptions& options = {});

}  // namespace hbvh
