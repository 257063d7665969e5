// SPDX-License-Identifier: MIT
// The umbrella header: the whole public API of hbvh::core and hbvh::io. Including single headers compiles faster.
#pragma once

// One line per public header, by layer (STYLE.md §1: geometry -> fit -> tree -> builders/query -> io).
// A new public header gets its line here. examples/collide_model compiles this file against the installed
// package (ctest -L install, tools/examples.sh).

#include <hbvh/version.hpp>
#include <hbvh/assert.hpp>
#include <hbvh/result.hpp>

// hbvh::core
#include <hbvh/files.hpp>
#include <hbvh/geometry/vector.hpp>
#include <hbvh/geometry/aabb.hpp>
#include <hbvh/geometry/obb.hpp>
#include <hbvh/geometry/sphere.hpp>
#include <hbvh/geometry/capsule.hpp>
#include <hbvh/geometry/bounding_volume.hpp>
#include <hbvh/geometry/primitive.hpp>
#include <hbvh/geometry/overlap.hpp>
#include <hbvh/geometry/validation.hpp>

#include <hbvh/fit/fit.hpp>
#include <hbvh/fit/fit_fast.hpp>
#include <hbvh/fit/volume_policy.hpp>

#include <hbvh/tree/bvh.hpp>
#include <hbvh/tree/binary_format.hpp>
#include <hbvh/tree/refit.hpp>
#include <hbvh/tree/stats.hpp>
#include <hbvh/tree/validate.hpp>

// The builders: build.hpp (build(), Algorithm) and the registry first, then one header per builder.
#include <hbvh/builders/auto.hpp>
#include <hbvh/builders/binned.hpp>
#include <hbvh/builders/bnb_enlarge.hpp>
#include <hbvh/builders/bnb_exact.hpp>
#include <hbvh/builders/bnb_tightest.hpp>
#include <hbvh/builders/budget.hpp>
#include <hbvh/builders/build.hpp>
#include <hbvh/builders/context.hpp>
#include <hbvh/builders/fast.hpp>
#include <hbvh/builders/insertion.hpp>
#include <hbvh/builders/insertion_haber.hpp>
#include <hbvh/builders/merge.hpp>
#include <hbvh/builders/obbtree.hpp>
#include <hbvh/builders/optimal.hpp>
#include <hbvh/builders/registry.hpp>
#include <hbvh/builders/report.hpp>
#include <hbvh/builders/scale.hpp>
#include <hbvh/builders/split.hpp>
#include <hbvh/builders/treelet.hpp>
#include <hbvh/builders/two_level.hpp>

#include <hbvh/query/tandem_traversal.hpp>
#include <hbvh/query/simulate.hpp>

#include <hbvh/scene/generate.hpp>

// hbvh::io. An installed package built with HBVH_BUILD_IO=OFF has no io headers: this part is then left out.
#if __has_include(<hbvh/io/xml.hpp>)
#include <hbvh/io/file.hpp>
#include <hbvh/io/xml.hpp>
#include <hbvh/io/xml_memory.hpp>
#include <hbvh/io/import.hpp>
#include <hbvh/io/model_file.hpp>
#include <hbvh/io/mjcf.hpp>
#include <hbvh/io/urdf.hpp>
#include <hbvh/io/mesh_import.hpp>
#include <hbvh/io/solid_shapes.hpp>
#include <hbvh/io/bv_mesh.hpp>
#include <hbvh/io/level_view.hpp>
#include <hbvh/io/export_dot.hpp>
#include <hbvh/io/export_gltf.hpp>
#include <hbvh/io/view_html.hpp>
#endif
