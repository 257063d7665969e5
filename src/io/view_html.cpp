// SPDX-License-Identifier: MIT
// The HTML level viewer: the page template with its canvas renderer, and the JSON it draws.
#include "hbvh/io/view_html.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

#include "hbvh/io/level_view.hpp"
#include "hbvh/tree/stats.hpp"

namespace hbvh {
namespace {

using nlohmann::json;

/// Text for HTML element content and attribute values.
std::string escape_html(std::string_view text) {
    std::string out;
    for (char c : text) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&#39;"; break;
            default: out += c;
        }
    }
    return out;
}

// The page before the title, between title and data, and after the data. The script reads the JSON
// block, so the template itself holds no model-specific text.
constexpr std::string_view page_head = R"HTML(<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>)HTML";

constexpr std::string_view page_middle = R"HTML(</title>
<style>
  html, body { margin: 0; height: 100%; overflow: hidden; background: #fafafa; font: 13px/1.35 system-ui, sans-serif; color: #222; }
  #view { position: absolute; inset: 0; width: 100%; height: 100%; cursor: grab; touch-action: none; }
  #panel { position: absolute; left: 10px; top: 10px; width: 250px; padding: 8px 10px; background: rgba(255,255,255,0.88);
           border: 1px solid #ccc; border-radius: 6px; }
  #panel h1 { font-size: 15px; margin: 0 0 6px 0; overflow-wrap: anywhere; }
  #panel input { width: 100%; }
  #panel table { border-collapse: collapse; width: 100%; margin-top: 4px; }
  #panel td { padding: 1px 0; vertical-align: top; }
  #panel td.value { text-align: right; font-variant-numeric: tabular-nums; }
  #swatch { display: inline-block; width: 11px; height: 11px; border-radius: 2px; vertical-align: -1px; margin-right: 4px; }
  #hint { color: #777; font-size: 11px; margin-top: 6px; }
</style>
</head>
<body>
<canvas id="view"></canvas>
<div id="panel">
  <h1 id="heading"></h1>
  <div><span id="swatch"></span><b id="level-name"></b></div>
  <input id="level" type="range" min="0" max="0" step="1" value="0" aria-label="level">
  <table id="stats"></table>
  <div id="hint">drag: rotate &middot; wheel: zoom &middot; &larr;/&rarr;: level &middot; URL #level=N, or #all for every level</div>
</div>
<script type="application/json" id="hbvh-data">)HTML";

constexpr std::string_view page_tail = R"HTML(</script>
<script>
"use strict";
(function () {
  const data = JSON.parse(document.getElementById("hbvh-data").textContent);
  const canvas = document.getElementById("view");
  const context = canvas.getContext("2d");
  const slider = document.getElementById("level");
  const levelCount = data.levels.length;

  // Geometry: dequantise once; boxes are drawn as quads (4 vertices per face, see triangulate()).
  const volumes = data.bvs.map(function (bv) {
    const points = new Float64Array(bv.p.length);
    for (let i = 0; i < bv.p.length; ++i) points[i] = data.origin[i % 3] + bv.p[i] * data.quantum;
    const polygons = [];
    if (bv.type === "aabb" || bv.type === "obb") {
      for (let face = 0; face < 6; ++face) polygons.push([4 * face, 4 * face + 1, 4 * face + 2, 4 * face + 3]);
    } else {
      for (let t = 0; t < bv.i.length; t += 3) polygons.push([bv.i[t], bv.i[t + 1], bv.i[t + 2]]);
    }
    return { points: points, polygons: polygons, box: bv.type === "aabb" || bv.type === "obb" };
  });
  const leafIndices = [];
  data.bvs.forEach(function (bv, index) { if (bv.leaf) leafIndices.push(index); });

  const centre = [0, 1, 2].map(function (k) { return 0.5 * (data.bounds[0][k] + data.bounds[1][k]); });
  const radius = Math.max(1e-12, 0.5 * Math.hypot(data.bounds[1][0] - data.bounds[0][0],
      data.bounds[1][1] - data.bounds[0][1], data.bounds[1][2] - data.bounds[0][2]));
  const view = { level: 0, yaw: -0.6, pitch: 0.45, zoom: 1, all: false };

  function rgba(rgb, alpha, scale) {
    return "rgba(" + Math.round(255 * Math.min(1, rgb[0] * scale)) + "," + Math.round(255 * Math.min(1, rgb[1] * scale)) +
        "," + Math.round(255 * Math.min(1, rgb[2] * scale)) + "," + alpha + ")";
  }

  // What level d shows: the primitives inside its inner nodes (solid grey), its own nodes in the level
  // colour (inner ones translucent), and the leaves carried from above in the carried grey.
  function drawList(depth) {
    const level = data.levels[depth];
    const shown = new Set();
    const list = [];
    level.nodes.forEach(function (index) {
      const leaf = data.bvs[index].leaf;
      list.push({ bv: index, rgb: data.colors[depth], alpha: leaf ? 0.8 : 0.25, edge: !leaf });
      if (leaf) shown.add(index);
    });
    level.carried.forEach(function (index) {
      list.push({ bv: index, rgb: data.carried_color, alpha: 0.7, edge: false });
      shown.add(index);
    });
    leafIndices.forEach(function (index) {
      if (!shown.has(index)) list.push({ bv: index, rgb: [0.47, 0.49, 0.53], alpha: 0.92, edge: false });
    });
    return list;
  }

  // Draws level `depth` into the canvas rectangle (x0, y0, width, height).
  function drawScene(depth, x0, y0, width, height, ratio) {
    // Camera: rotate the model about its centre (yaw about +y, then pitch about +x), then a perspective
    // projection from distance 3 radii, scaled so the bounding sphere fills most of the rectangle.
    const cy = Math.cos(view.yaw), sy = Math.sin(view.yaw), cp = Math.cos(view.pitch), sp = Math.sin(view.pitch);
    const distance = 3 * radius;
    const focal = 0.46 * Math.min(width, height) * (distance - radius) / radius * view.zoom;
    const light = [0.35, 0.55, 0.76];
    const polygons = [];
    drawList(depth).forEach(function (item) {
      const volume = volumes[item.bv];
      const count = volume.points.length / 3;
      const camera = new Float64Array(3 * count), screen = new Float64Array(2 * count);
      for (let v = 0; v < count; ++v) {
        const x = volume.points[3 * v] - centre[0], y = volume.points[3 * v + 1] - centre[1], z = volume.points[3 * v + 2] - centre[2];
        const x1 = cy * x + sy * z, z1 = -sy * x + cy * z;
        const y2 = cp * y - sp * z1, z2 = sp * y + cp * z1;
        camera[3 * v] = x1; camera[3 * v + 1] = y2; camera[3 * v + 2] = z2;
        const w = distance - z2;
        screen[2 * v] = x0 + 0.5 * width + focal * x1 / w;
        screen[2 * v + 1] = y0 + 0.5 * height - focal * y2 / w;
      }
      volume.polygons.forEach(function (polygon) {
        const a = polygon[0], b = polygon[1], c = polygon[2];
        const ux = camera[3 * b] - camera[3 * a], uy = camera[3 * b + 1] - camera[3 * a + 1], uz = camera[3 * b + 2] - camera[3 * a + 2];
        const vx = camera[3 * c] - camera[3 * a], vy = camera[3 * c + 1] - camera[3 * a + 1], vz = camera[3 * c + 2] - camera[3 * a + 2];
        const nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
        const length = Math.hypot(nx, ny, nz);
        // Two-sided Lambert: translucent volumes show their inside too.
        const shade = length > 0 ? 0.55 + 0.5 * Math.abs((nx * light[0] + ny * light[1] + nz * light[2]) / length) : 0.8;
        let depthSum = 0;
        polygon.forEach(function (v) { depthSum += camera[3 * v + 2]; });
        polygons.push({ item: item, screen: screen, polygon: polygon, shade: shade, depth: depthSum / polygon.length });
      });
    });
    // Painter's algorithm: farthest first (smallest camera z, as the camera looks down -z from +z).
    polygons.sort(function (p, q) { return p.depth - q.depth; });
    context.lineJoin = "round";
    polygons.forEach(function (p) {
      context.beginPath();
      p.polygon.forEach(function (v, k) {
        if (k === 0) context.moveTo(p.screen[2 * v], p.screen[2 * v + 1]);
        else context.lineTo(p.screen[2 * v], p.screen[2 * v + 1]);
      });
      context.closePath();
      context.fillStyle = rgba(p.item.rgb, p.item.alpha, p.shade);
      context.fill();
      if (p.item.edge && p.polygon.length === 4) {
        context.strokeStyle = rgba(p.item.rgb, 0.9, 0.6);
        context.lineWidth = ratio;
        context.stroke();
      }
    });
  }

  function render() {
    const ratio = window.devicePixelRatio || 1;
    const width = Math.max(1, Math.floor(canvas.clientWidth * ratio));
    const height = Math.max(1, Math.floor(canvas.clientHeight * ratio));
    if (canvas.width !== width || canvas.height !== height) { canvas.width = width; canvas.height = height; }
    context.setTransform(1, 0, 0, 1, 0, 0);
    context.fillStyle = "#fafafa";
    context.fillRect(0, 0, width, height);
    if (levelCount === 0) return;
    if (!view.all) { drawScene(view.level, 0, 0, width, height, ratio); return; }
    // All levels side by side, like the survey's Figures 14-15: a grid of tiles, each labelled.
    const columns = Math.ceil(Math.sqrt(levelCount * width / height));
    const rows = Math.ceil(levelCount / columns);
    const tileWidth = width / columns, tileHeight = height / rows;
    for (let depth = 0; depth < levelCount; ++depth) {
      const x0 = (depth % columns) * tileWidth, y0 = Math.floor(depth / columns) * tileHeight;
      context.save();
      context.beginPath();
      context.rect(x0, y0, tileWidth, tileHeight);
      context.clip();
      drawScene(depth, x0, y0, tileWidth, tileHeight, ratio);
      context.restore();
      context.fillStyle = rgba(data.colors[depth], 1, 0.7);
      context.font = "bold " + Math.round(15 * ratio) + "px system-ui, sans-serif";
      context.fillText("level " + depth, x0 + 12 * ratio, y0 + tileHeight - 12 * ratio);
    }
  }

  function format(value) {
    if (value === 0) return "0";
    const magnitude = Math.abs(value);
    return magnitude >= 1e5 || magnitude < 1e-3 ? value.toExponential(3) : String(Number(value.toPrecision(4)));
  }

  function showStats() {
    const level = data.levels[view.level];
    const types = {};
    level.nodes.forEach(function (index) { const t = data.bvs[index].type; types[t] = (types[t] || 0) + 1; });
    const share = data.cost > 0 ? " (" + (100 * level.cost / data.cost).toFixed(1) + "%)" : "";
    const rows = [
      ["nodes on this level", level.nodes.length + " (" + level.inner + " inner, " + (level.nodes.length - level.inner) + " leaves)"],
      ["carried leaves (grey)", String(level.carried.length)],
      ["sum of volumes", format(level.volume)],
      ["cost contribution", format(level.cost) + share],
      ["types", Object.keys(types).sort().map(function (t) { return types[t] + " " + t; }).join(", ")],
      ["total cost (Eq. 2)", format(data.cost)],
      ["primitives / nodes", data.primitives + " / " + data.nodes]
    ];
    const table = document.getElementById("stats");
    table.textContent = "";
    rows.forEach(function (row) {
      const tr = document.createElement("tr");
      const name = document.createElement("td"), value = document.createElement("td");
      name.textContent = row[0]; value.textContent = row[1]; value.className = "value";
      tr.appendChild(name); tr.appendChild(value); table.appendChild(tr);
    });
    document.getElementById("level-name").textContent = "level " + view.level + " of " + (levelCount - 1);
    document.getElementById("swatch").style.background = rgba(data.colors[view.level], 1, 1);
  }

  function setLevel(level, updateHash) {
    if (levelCount === 0) return;
    view.level = Math.max(0, Math.min(levelCount - 1, level | 0));
    slider.value = String(view.level);
    if (updateHash) {
      view.all = false;
      document.getElementById("panel").style.display = "";
      history.replaceState(null, "", "#level=" + view.level);
    }
    showStats();
    render();
  }

  function levelFromHash() {
    // "#all" shows every level at once (the panel is hidden then): handy for pictures of a whole tree.
    view.all = /(^#|&)all\b/.test(window.location.hash);
    document.getElementById("panel").style.display = view.all ? "none" : "";
    const match = /level=(\d+)/.exec(window.location.hash);
    return match ? parseInt(match[1], 10) : 0;
  }

  document.getElementById("heading").textContent = data.title;
  slider.max = String(Math.max(0, levelCount - 1));
  slider.addEventListener("input", function () { setLevel(parseInt(slider.value, 10), true); });
  window.addEventListener("hashchange", function () { setLevel(levelFromHash(), false); });
  window.addEventListener("resize", render);
  window.addEventListener("keydown", function (event) {
    if (event.key === "ArrowRight" || event.key === "ArrowUp") setLevel(view.level + 1, true);
    if (event.key === "ArrowLeft" || event.key === "ArrowDown") setLevel(view.level - 1, true);
  });
  let drag = null;
  canvas.addEventListener("pointerdown", function (event) {
    drag = { x: event.clientX, y: event.clientY };
    canvas.setPointerCapture(event.pointerId);
  });
  canvas.addEventListener("pointermove", function (event) {
    if (!drag) return;
    view.yaw += 0.01 * (event.clientX - drag.x);
    view.pitch = Math.max(-1.5, Math.min(1.5, view.pitch + 0.01 * (event.clientY - drag.y)));
    drag = { x: event.clientX, y: event.clientY };
    render();
  });
  canvas.addEventListener("pointerup", function () { drag = null; });
  canvas.addEventListener("wheel", function (event) {
    event.preventDefault();
    view.zoom = Math.max(0.1, Math.min(20, view.zoom * Math.exp(-0.001 * event.deltaY)));
    render();
  }, { passive: false });
  if (levelCount === 0) {
    document.getElementById("level-name").textContent = "empty hierarchy";
    render();
    return;
  }
  setLevel(levelFromHash(), false);
})();
</script>
</body>
</html>
)HTML";

}  // namespace

std::string export_html(const Bvh& bvh, std::string_view title, const HtmlOptions& options) {
    // Stage 1: bounds of everything drawn, and the quantisation grid over them.
    Aabb bounds = Aabb::empty();
    for (const Node& node : bvh.nodes) bounds = bounds.merged(world_aabb(node.volume));
    if (bvh.empty()) bounds = {Vec3::Zero(), Vec3::Zero()};
    const double size = (bounds.max - bounds.min).maxCoeff();
    const double quantum = size > 0.0 ? size / 1048576.0 : 1.0;  // 2^-20 of the model: far below a pixel

    // Stage 2: per node its type, label data and mesh in grid units.
    const MeshDetail detail =
        bvh.nodes.size() > options.coarse_above_nodes ? MeshDetail{8, 4} : options.detail;
    json bvs = json::array();
    for (const Node& node : bvh.nodes) {
        const TriangleMesh mesh = triangulate(node.volume, detail);
        json points = json::array();
        for (const Vec3& p : mesh.positions)
            for (Eigen::Index k = 0; k < 3; ++k) points.push_back(std::llround((p[k] - bounds.min[k]) / quantum));
        json entry = {{"type", to_string(type_of(node.volume))},
                      {"leaf", node.is_leaf()},
                      {"volume", volume(node.volume)},
                      {"p", std::move(points)}};
        // Boxes are drawn from their fixed 4-per-face layout, so their indices need not be stored.
        if (!std::holds_alternative<Aabb>(node.volume) && !std::holds_alternative<Obb>(node.volume))
            entry["i"] = mesh.indices;
        else
            entry["i"] = json::array();
        if (node.is_leaf()) {
            entry["primitive"] = node.primitive;
            entry["name"] = bvh.primitives[node.primitive].name;
        }
        bvs.push_back(std::move(entry));
    }

    // Stage 3: levels with their statistics and colours.
    json levels = json::array();
    json colors = json::array();
    for (const LevelView& view : level_views(bvh)) {
        levels.push_back({{"depth", view.depth}, {"nodes", view.nodes}, {"carried", view.carried},
                          {"inner", view.inner_count}, {"volume", view.volume}, {"cost", view.cost}});
        const Rgb color = level_color(view.depth);
        colors.push_back({color[0], color[1], color[2]});
    }
    const Rgb carried = carried_color();
    const json data = {{"title", std::string(title)},
                       {"cost", cost(bvh)},
                       {"primitives", bvh.primitives.size()},
                       {"nodes", bvh.nodes.size()},
                       {"origin", {bounds.min.x(), bounds.min.y(), bounds.min.z()}},
                       {"quantum", quantum},
                       {"bounds", {{bounds.min.x(), bounds.min.y(), bounds.min.z()},
                                   {bounds.max.x(), bounds.max.y(), bounds.max.z()}}},
                       {"colors", std::move(colors)},
                       {"carried_color", {carried[0], carried[1], carried[2]}},
                       {"levels", std::move(levels)},
                       {"bvs", std::move(bvs)}};

    // A "<" inside the JSON (only possible in strings) could end or confuse the script element
    // ("</script>", "<!--"); "\u003c" is the same string to JSON.parse.
    const std::string text = data.dump(-1, ' ', false, json::error_handler_t::replace);
    std::string safe;
    safe.reserve(text.size());
    for (char c : text) {
        if (c == '<')
            safe += "\\u003c";
        else
            safe += c;
    }
    std::string page;
    page.reserve(page_head.size() + page_middle.size() + page_tail.size() + safe.size() + title.size());
    page.append(page_head).append(escape_html(title)).append(page_middle).append(safe).append(page_tail);
    return page;
}

}  // namespace hbvh
