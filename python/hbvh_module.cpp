// SPDX-License-Identifier: MIT
// The `hbvh` Python module: numpy arrays in and out of hbvh's public API, errors as hbvh.Error (a ValueError).
//
// A thin layer (STYLE.md §11): every check and every computation is the library's; this file converts arrays,
// dispatches on file names as the CLI does, and releases the GIL around builds and batches of queries.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "hbvh/hbvh.hpp"

namespace py = pybind11;
using namespace pybind11::literals;

namespace hbvh::python {
namespace {

/// hbvh.Error's C++ side: carries Error::to_string(), the text the CLI prints after "hbvh: ".
class BindingError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// `text` as a Python str, each byte that starts no UTF-8 character as U+FFFD: names and paths come from files and
/// may be Latin-1, and pybind11's strict decoding made them an empty hbvh.Error message or a UnicodeDecodeError.
py::str text_of(const std::string& text) {
    PyObject* decoded = PyUnicode_DecodeUTF8(text.data(), static_cast<Py_ssize_t>(text.size()), "replace");
    if (decoded == nullptr) throw py::error_already_set();
    return py::reinterpret_steal<py::str>(decoded);
}

/// `text` with each byte that starts no UTF-8 character replaced by U+FFFD, as UTF-8 again.
std::string valid_utf8(const std::string& text) { return text_of(text).cast<std::string>(); }

[[noreturn]] void raise(const Error& error) { throw BindingError(valid_utf8(error.to_string())); }

/// A primitive set as Python sees it: a list of primitives, plus the importer's notes about skipped input.
struct Primitives {
    std::vector<Primitive> items;
    std::vector<std::string> warnings;
};

/// A hierarchy with its query layout, converted once (QueryTree::create checks the structure).
struct Hierarchy {
    Bvh bvh;
    QueryTree tree;
    std::vector<int> node_lines;  ///< For a hierarchy read from XML: each node's line (names violations).

    static Hierarchy from(Bvh bvh, std::vector<int> node_lines = {}) {
        Result<QueryTree> tree = QueryTree::create(bvh);
        if (!tree) raise(tree.error());
        return Hierarchy{std::move(bvh), std::move(tree.value()), std::move(node_lines)};
    }
};

// Stage 1: numpy arrays in.

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::string shape_text(const py::array& array) {
    std::string text = "(";
    for (py::ssize_t i = 0; i < array.ndim(); ++i) text += (i ? ", " : "") + std::to_string(array.shape(i));
    return text + (array.ndim() == 1 ? ",)" : ")");
}

/// `object` (an array or anything numpy makes one of) as C-contiguous doubles, when it holds integers or floats:
/// forcecast alone also turned booleans, complex numbers (dropping the imaginary part), dates, strings and None
/// into numbers, and read a masked array's hidden values.
DoubleArray numbers_array(const py::handle& object, const char* name) {
    const py::array raw = py::array::ensure(object);
    if (!raw) throw py::value_error(std::string(name) + " must be an array of numbers");
    const char kind = raw.dtype().kind();
    if (kind != 'i' && kind != 'u' && kind != 'f')
        throw py::value_error(std::string(name) + " must hold integers or floats, not dtype " +
                              py::str(raw.dtype()).cast<std::string>());
    if (py::hasattr(object, "mask"))
        throw py::value_error(std::string(name) + " is a masked array: fill it first (numpy.ma.filled)");
    return DoubleArray::ensure(raw);
}

/// Whether `object`'s numbers are floats narrower than double: a float32 rotation is off a rotation by its
/// rounding (a few 1e-8), far beyond the library's 1e-9, and is replaced by the nearest one (float32_rotation_repaired).
bool narrow_floats(const py::handle& object) {
    const py::array raw = py::array::ensure(object);
    return raw && raw.dtype().kind() == 'f' && raw.dtype().itemsize() < 8;
}

/// The proper rotation nearest `m` (hbvh::nearest_rotation) when `m` is one up to single-precision rounding
/// (|R^T R - I| <= 1e-5, det > 0); `m` itself otherwise, which validation then refuses in its own words.
Mat3 float32_rotation_repaired(const Mat3& m) {
    if (!m.allFinite() || !((m.transpose() * m - Mat3::Identity()).cwiseAbs().maxCoeff() <= 1e-5) || !(m.determinant() > 0.0))
        return m;
    return nearest_rotation(m);
}

/// `object` as a C-contiguous double array of shape `shape` (-1: any length, the same N for every argument).
DoubleArray checked_array(const py::handle& object, const char* name, std::vector<py::ssize_t> shape, py::ssize_t& n) {
    DoubleArray array = numbers_array(object, name);
    bool ok = array.ndim() == static_cast<py::ssize_t>(shape.size());
    for (std::size_t i = 0; ok && i < shape.size(); ++i) {
        if (shape[i] >= 0) {
            ok = array.shape(static_cast<py::ssize_t>(i)) == shape[i];
        } else if (n < 0) {
            n = array.shape(static_cast<py::ssize_t>(i));
        } else {
            ok = array.shape(static_cast<py::ssize_t>(i)) == n;
        }
    }
    if (!ok) {
        std::string wanted = "(";
        for (std::size_t i = 0; i < shape.size(); ++i)
            wanted += (i ? ", " : "") + (shape[i] < 0 ? (n < 0 ? std::string("N") : std::to_string(n)) : std::to_string(shape[i]));
        throw py::value_error(std::string(name) + " must have shape " + wanted + (shape.size() == 1 ? ",)" : ")") +
                              ", got " + shape_text(array));
    }
    return array;
}

Vec3 vec3_at(const DoubleArray& array, py::ssize_t row) {
    const double* p = array.data() + 3 * row;
    return {p[0], p[1], p[2]};
}

Mat3 mat3_at(const DoubleArray& array, py::ssize_t row) {
    const double* p = array.data() + 9 * row;
    Mat3 m;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) m(r, c) = p[3 * r + c];
    return m;
}

/// Radii of shape (N,), or one number for all.
std::vector<double> radii_of(const py::handle& object, py::ssize_t& n) {
    DoubleArray array = numbers_array(object, "radii");
    if (array && array.ndim() == 0 && n >= 0) return std::vector<double>(static_cast<std::size_t>(n), *array.data());
    array = checked_array(object, "radii", {-1}, n);
    return {array.data(), array.data() + n};
}

/// Names, one per primitive, or none.
std::vector<std::string> names_of(const std::optional<std::vector<std::string>>& names, py::ssize_t n) {
    if (!names) return std::vector<std::string>(static_cast<std::size_t>(n));
    if (static_cast<py::ssize_t>(names->size()) != n)
        throw py::value_error("names must have one entry per primitive (" + std::to_string(n) + "), got " +
                              std::to_string(names->size()));
    return *names;
}

/// The primitives, checked by validate_primitives (indices are rows of these arrays).
Primitives checked(std::vector<Primitive> items) {
    if (Status valid = validate_primitives(items); !valid) raise(valid.error());
    return Primitives{std::move(items), {}};
}

Primitives make_boxes(const py::handle& centers_in, const py::handle& half_extents_in, const py::handle& rotations_in,
                      const std::optional<std::vector<std::string>>& names_in) {
    py::ssize_t n = -1;
    const DoubleArray centers = checked_array(centers_in, "centers", {-1, 3}, n);
    const DoubleArray half_extents = checked_array(half_extents_in, "half_extents", {-1, 3}, n);
    std::optional<DoubleArray> rotations;
    if (!rotations_in.is_none()) rotations = checked_array(rotations_in, "rotations", {-1, 3, 3}, n);
    const bool round_rotations = !rotations_in.is_none() && narrow_floats(rotations_in);
    std::vector<std::string> names = names_of(names_in, n);
    std::vector<Primitive> items;
    items.reserve(static_cast<std::size_t>(n));
    for (py::ssize_t i = 0; i < n; ++i) {
        const Vec3 center = vec3_at(centers, i);
        const Vec3 half = vec3_at(half_extents, i);
        // A double rotation accepted within rotation_tolerance is stored as its nearest rotation too: the fitters
        // place a box's corners with R and the exact tests map points back with R^T, which differ by the
        // matrix's error times the box's size (4e-10 of a 1000-unit box gave pairs that depended on the tree).
        const auto rotation = [&] {
            const Mat3 given = mat3_at(*rotations, i);
            if (round_rotations) return float32_rotation_repaired(given);
            return rotation_problem(given).empty() ? exact_rotation(given) : given;
        };
        // Without rotations a box is axis-aligned: an Aabb primitive, as in the survey's XML.
        BoundingVolume volume = rotations ? BoundingVolume(Obb{center, rotation(), half})
                                          : BoundingVolume(Aabb{center - half, center + half});
        items.push_back({std::move(volume), std::move(names[static_cast<std::size_t>(i)])});
    }
    return checked(std::move(items));
}

Primitives make_spheres(const py::handle& centers_in, const py::handle& radii_in,
                        const std::optional<std::vector<std::string>>& names_in) {
    py::ssize_t n = -1;
    const DoubleArray centers = checked_array(centers_in, "centers", {-1, 3}, n);
    const std::vector<double> radii = radii_of(radii_in, n);
    std::vector<std::string> names = names_of(names_in, n);
    std::vector<Primitive> items;
    items.reserve(static_cast<std::size_t>(n));
    for (py::ssize_t i = 0; i < n; ++i)
        items.push_back({Sphere{vec3_at(centers, i), radii[static_cast<std::size_t>(i)]},
                         std::move(names[static_cast<std::size_t>(i)])});
    return checked(std::move(items));
}

Primitives make_capsules(const py::handle& p0_in, const py::handle& p1_in, const py::handle& radii_in,
                         const std::optional<std::vector<std::string>>& names_in) {
    py::ssize_t n = -1;
    const DoubleArray p0 = checked_array(p0_in, "p0", {-1, 3}, n);
    const DoubleArray p1 = checked_array(p1_in, "p1", {-1, 3}, n);
    const std::vector<double> radii = radii_of(radii_in, n);
    std::vector<std::string> names = names_of(names_in, n);
    std::vector<Primitive> items;
    items.reserve(static_cast<std::size_t>(n));
    for (py::ssize_t i = 0; i < n; ++i)
        items.push_back({Capsule{vec3_at(p0, i), vec3_at(p1, i), radii[static_cast<std::size_t>(i)]},
                         std::move(names[static_cast<std::size_t>(i)])});
    return checked(std::move(items));
}

/// A Primitives, or a list / tuple of them, joined in order.
Primitives joined(const py::handle& object) {
    if (py::isinstance<Primitives>(object)) return object.cast<const Primitives&>();
    if (!py::isinstance<py::list>(object) && !py::isinstance<py::tuple>(object))
        throw py::type_error("expected hbvh.Primitives or a list of them");
    Primitives all;
    for (const py::handle& part : object) {
        if (!py::isinstance<Primitives>(part)) throw py::type_error("expected hbvh.Primitives or a list of them");
        const auto& items = part.cast<const Primitives&>().items;
        all.items.insert(all.items.end(), items.begin(), items.end());
    }
    return all;
}

/// A pose: None (identity), a 4x4 matrix [R t; 0 0 0 1], or a tuple (R (3, 3), t (3,)). The rotation itself is
/// checked by collide() (validate_pose).
RigidTransform pose_of(const py::handle& object, const char* name) {
    if (object.is_none()) return RigidTransform::identity();
    py::ssize_t unused = -1;
    if (py::isinstance<py::tuple>(object) && py::len(object) == 2) {
        const auto parts = object.cast<py::tuple>();
        // Each part is named in its errors: "pose_a must have shape (3,)" did not say it was the translation.
        const std::string rotation_name = std::string(name) + "'s rotation R of (R, t)";
        const std::string translation_name = std::string(name) + "'s translation t of (R, t)";
        const DoubleArray rotation = checked_array(parts[0], rotation_name.c_str(), {3, 3}, unused);
        const DoubleArray translation = checked_array(parts[1], translation_name.c_str(), {3}, unused);
        const Mat3 r = mat3_at(rotation, 0);
        return {narrow_floats(parts[0]) ? float32_rotation_repaired(r) : r, vec3_at(translation, 0)};
    }
    const DoubleArray matrix = checked_array(object, name, {4, 4}, unused);
    const double* m = matrix.data();
    if (m[12] != 0.0 || m[13] != 0.0 || m[14] != 0.0 || m[15] != 1.0)
        throw py::value_error(std::string(name) + ": the last row of a 4x4 pose must be 0 0 0 1");
    RigidTransform pose;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) pose.rotation(r, c) = m[4 * r + c];
        pose.translation(r) = m[4 * r + 3];
    }
    if (narrow_floats(object)) pose.rotation = float32_rotation_repaired(pose.rotation);
    return pose;
}

// Stage 2: numpy arrays out.

/// One volume as a record of the structured arrays Primitives.array and Hierarchy.nodes.
struct VolumeRecord {
    std::uint8_t type;      ///< BvType: 0 aabb, 1 obb, 2 sphere, 3 capsule.
    std::uint32_t first_child;
    std::uint32_t child_count;
    std::uint32_t primitive;
    double center[3];       ///< Box / sphere centre, capsule midpoint.
    double rotation[9];     ///< Box axes as columns (identity for all but an Obb), row-major 3x3.
    double half_extents[3]; ///< Boxes; zero otherwise.
    double radius;          ///< Spheres and capsules; zero otherwise.
    double p0[3];           ///< Capsule end points; zero otherwise.
    double p1[3];
};

VolumeRecord record_of(const BoundingVolume& volume) {
    VolumeRecord r{};
    r.type = static_cast<std::uint8_t>(type_of(volume));
    Vec3 center = Vec3::Zero(), half = Vec3::Zero(), p0 = Vec3::Zero(), p1 = Vec3::Zero();
    Mat3 rotation = Mat3::Identity();
    std::visit(Overloaded{[&](const Aabb& b) { center = b.center(), half = b.half_extents(); },
                          [&](const Obb& b) { center = b.center, rotation = b.rotation, half = b.half_extents; },
                          [&](const Sphere& s) { center = s.center, r.radius = s.radius; },
                          [&](const Capsule& c) {
                              center = 0.5 * (c.p0 + c.p1), p0 = c.p0, p1 = c.p1, r.radius = c.radius;
                          }},
               volume);
    for (int i = 0; i < 3; ++i) {
        r.center[i] = center(i), r.half_extents[i] = half(i), r.p0[i] = p0(i), r.p1[i] = p1(i);
        for (int j = 0; j < 3; ++j) r.rotation[3 * i + j] = rotation(i, j);
    }
    return r;
}

/// The numpy dtype of VolumeRecord, with the tree fields or without them (Primitives.array).
py::dtype record_dtype(bool tree_fields) {
    py::list names, formats, offsets;
    const auto add = [&](const char* name, py::object format, std::size_t offset) {
        names.append(name), formats.append(std::move(format)), offsets.append(offset);
    };
    const auto f8 = [](py::tuple shape) { return py::make_tuple("<f8", shape); };
    add("type", py::str("u1"), offsetof(VolumeRecord, type));
    if (tree_fields) {
        add("first_child", py::str("<u4"), offsetof(VolumeRecord, first_child));
        add("child_count", py::str("<u4"), offsetof(VolumeRecord, child_count));
        add("primitive", py::str("<u4"), offsetof(VolumeRecord, primitive));
    }
    add("center", f8(py::make_tuple(3)), offsetof(VolumeRecord, center));
    add("rotation", f8(py::make_tuple(3, 3)), offsetof(VolumeRecord, rotation));
    add("half_extents", f8(py::make_tuple(3)), offsetof(VolumeRecord, half_extents));
    add("radius", py::str("<f8"), offsetof(VolumeRecord, radius));
    add("p0", f8(py::make_tuple(3)), offsetof(VolumeRecord, p0));
    add("p1", f8(py::make_tuple(3)), offsetof(VolumeRecord, p1));
    py::dict spec("names"_a = names, "formats"_a = formats, "offsets"_a = offsets, "itemsize"_a = sizeof(VolumeRecord));
    return py::module_::import("numpy").attr("dtype")(spec).cast<py::dtype>();
}

py::array records(const std::vector<VolumeRecord>& rows, bool tree_fields) {
    py::array out(record_dtype(tree_fields), std::vector<py::ssize_t>{static_cast<py::ssize_t>(rows.size())});
    if (!rows.empty()) std::memcpy(out.mutable_data(), rows.data(), rows.size() * sizeof(VolumeRecord));
    return out;
}

py::array primitive_array(const Primitives& primitives) {
    std::vector<VolumeRecord> rows;
    rows.reserve(primitives.items.size());
    for (const Primitive& p : primitives.items) rows.push_back(record_of(p.volume));
    return records(rows, false);
}

py::array node_array(const Bvh& bvh) {
    std::vector<VolumeRecord> rows;
    rows.reserve(bvh.nodes.size());
    for (const Node& node : bvh.nodes) {
        VolumeRecord r = record_of(node.volume);
        r.first_child = node.first_child, r.child_count = node.child_count, r.primitive = node.primitive;
        rows.push_back(r);
    }
    return records(rows, true);
}

/// Overlapping pairs as an (N, 2) int64 array.
py::array_t<std::int64_t> pair_array(const CollideResult& result) {
    py::array_t<std::int64_t> out({static_cast<py::ssize_t>(result.pairs.size()), py::ssize_t{2}});
    std::int64_t* p = out.mutable_data();
    for (const auto& [i, j] : result.pairs) *p++ = i, *p++ = j;
    return out;
}

// Stage 3: files, as the CLI reads them (read_model_file; then the CLI's load_model checks).

/// Primitives or a Hierarchy from any file the CLI reads. `format` as the CLI's --format.
/// Paths are str or os.PathLike (pathlib.Path), as open() takes them.
py::object load(const std::filesystem::path& file, const std::string& format, bool refit) {
    const std::string path = file.string();
    // An empty path named no file in its error ("cannot open for reading: No such file or directory").
    if (path.empty()) raise(Error{"path: the path is empty"});
    // The argument's own error, before the file is opened (the CLI's --format is a usage error too).
    if (std::string problem = input_format_problem(format); !problem.empty()) raise(Error{"format: " + problem});
    Result<ModelFile> read = read_model_file(path, format);
    if (!read) raise(read.error());
    // The checks of the CLI's load_model, then the containment check every CLI command but stats makes.
    if (Status checked = check_model_file(*read, path); !checked) raise(checked.error());
    if (!read->hierarchy) return py::cast(Primitives{std::move(read->primitives), std::move(read->warnings)});
    Result<Bvh> enclosing =
        enclosing_hierarchy(std::move(*read->hierarchy), read->node_lines, path, refit, "load(..., refit=True)");
    if (!enclosing) raise(enclosing.error());
    return py::cast(Hierarchy::from(std::move(enclosing).value(), std::move(read->node_lines)));
}

void save(const Hierarchy& h, const std::filesystem::path& file) {
    const std::string path = file.string();
    const Status written = lower_case_extension(path) == ".hbvh" ? write_binary_file(path, h.bvh)
                                                                  : write_file_atomic(path, write_xml(h.bvh));
    if (!written) raise(written.error());
}

// Stage 4: building, measuring, querying.

/// The CLI's --type-weight: "obb=1.3,capsule=1.2", "@FILE" (the weights `hbvh calibrate -o FILE` wrote), or a
/// dict {"obb": 1.3}; None leaves every weight 1.
Result<VolumePolicy> with_type_weights(const py::object& weights, VolumePolicy policy) {
    if (weights.is_none()) return policy;
    if (py::isinstance<py::dict>(weights)) {
        // Each entry on its own: joined into one "kind=weight,..." text, a key such as "obb=50,sphere" added a
        // weight of its own. An empty dict is no weights, as None.
        for (const auto& [kind, weight] : weights.cast<py::dict>()) {
            if (!py::isinstance<py::str>(kind)) throw py::value_error("type_weights keys must be BV kind names (str)");
            const std::string name = kind.cast<std::string>();
            if (name.find_first_of("=,@ \t\n") != std::string::npos)
                return Error{"unknown BV type '" + name + "' in type_weights (aabb, obb, sphere or capsule)"};
            // float() of a str or None raised a bare "could not convert string to float" naming neither.
            double value = 0.0;
            try {
                value = py::float_(py::reinterpret_borrow<py::object>(weight)).cast<double>();
            } catch (const py::error_already_set&) {
                throw py::type_error("type_weights['" + name + "'] must be a number, got " +
                                     py::repr(py::reinterpret_borrow<py::object>(weight)).cast<std::string>());
            }
            Result<VolumePolicy> one = parse_type_weights(name + "=" + py::repr(py::float_(value)).cast<std::string>(), policy);
            if (!one) return one;
            policy = one.value();
        }
        return policy;
    }
    if (!py::isinstance<py::str>(weights))
        throw py::value_error("type_weights must be a str ('obb=1.3,...' or '@FILE') or a dict, or None");
    return type_weights_from(weights.cast<std::string>(), policy);
}

Hierarchy build_hierarchy(const py::handle& primitives_in, const std::string& algorithm, const std::string& types,
                          double time_limit, bool refine, const std::string& objective, const py::object& type_weights) {
    const Primitives primitives = joined(primitives_in);
    const std::optional<Algorithm> chosen = parse_algorithm(algorithm);
    if (!chosen) raise(Error{"unknown algorithm '" + algorithm + "' (see `hbvh algorithms`)"});
    Result<VolumePolicy> policy = parse_allowed_types(types);
    if (!policy) raise(policy.error());
    policy = with_type_weights(type_weights, policy.value());
    if (!policy) raise(policy.error());
    if (!(time_limit >= 0.0)) throw py::value_error("time_limit must be a number of seconds >= 0 (0: no limit)");
    if (objective != "eq2" && objective != "calibrated")
        throw py::value_error("objective must be 'eq2' or 'calibrated', not '" + objective + "'");
    BuildContext context;
    context.policy = policy.value();
    if (objective == "calibrated") context.policy.measure = NodeMeasure::minkowski;
    BuildReport report;
    context.report = &report;
    std::optional<Result<Bvh>> built;
    {
        py::gil_scoped_release unlocked;
        const BuildContext timed = context.with_time_limit(time_limit);
        built = refine ? build_refined(primitives.items, *chosen, timed) : build(primitives.items, *chosen, timed);
    }
    if (!*built) raise(built->error());
    // As the CLI's warning: a tree of another builder than the one asked for is never silent.
    if (!report.substitution.empty() && PyErr_WarnEx(PyExc_UserWarning, report.substitution.c_str(), 1) != 0)
        throw py::error_already_set();  // the warning was turned into an error (warnings filter "error")
    // A build stopped by time_limit returns a tree all the same (the best so far, or the two-level one): say so,
    // as the CLI's --stats does, with the builder's own notes.
    // Some builders note the stop only among their notes (scale, the treelets), so budget_hit under a time limit
    // warns too, with those notes.
    std::string stopped = report.time_limit;
    if (stopped.empty() && report.budget_hit && time_limit > 0.0) {
        for (const std::string& note : report.notes)
            if (note.find("time limit") != std::string::npos) stopped += (stopped.empty() ? "" : "; ") + note;
        if (stopped.empty()) stopped = "the build stopped at its budget";
    }
    if (!stopped.empty() && PyErr_WarnEx(PyExc_UserWarning, valid_utf8("time_limit reached: " + stopped).c_str(), 1) != 0)
        throw py::error_already_set();
    return Hierarchy::from(std::move(built->value()));
}

py::dict summary_dict(const Summary& s) { return py::dict("min"_a = s.min, "mean"_a = s.mean, "max"_a = s.max); }

/// The keys of `hbvh stats --json`, in its order.
py::dict stats_dict(const Hierarchy& h) {
    const Stats stats = compute_stats(h.bvh);
    py::dict types;
    for (BvType type : all_bv_types) types[py::str(std::string(to_string(type)))] = stats.types[static_cast<std::size_t>(type)];
    py::list violations;
    for (const ContainmentViolation& v : containment_violations(h.bvh))
        violations.append(py::dict("node"_a = v.node, "line"_a = line_of_node(h.node_lines, v.node),
                                   "type"_a = std::string(to_string(type_of(h.bvh.nodes[v.node].volume))),
                                   "primitive"_a = v.primitive, "name"_a = h.bvh.primitives[v.primitive].name,
                                   "by"_a = v.protrusion, "message"_a = describe_violation(h.bvh, v)));
    py::dict out;
    out["cost"] = stats.cost, out["calibrated_cost"] = stats.calibrated_cost, out["height"] = stats.height, out["nodes"] = stats.nodes;
    out["inner_nodes"] = stats.inner_nodes, out["leaves"] = stats.leaves;
    out["branching"] = summary_dict(stats.branching), out["tightness"] = summary_dict(stats.tightness);
    out["leaf_depth"] = summary_dict(stats.leaf_depth), out["overlap"] = stats.overlap, out["types"] = types;
    out["violations"] = violations;
    return out;
}

CollideMode mode_of(bool first) { return first ? CollideMode::first : CollideMode::all; }

py::array_t<std::int64_t> collide_pair(const Hierarchy& a, const py::handle& pose_a, const Hierarchy& b,
                                       const py::handle& pose_b, bool first) {
    const RigidTransform ta = pose_of(pose_a, "pose_a"), tb = pose_of(pose_b, "pose_b");
    CollideResult result;
    {
        py::gil_scoped_release unlocked;
        collide(a.tree, ta, b.tree, tb, mode_of(first), result);
    }
    if (result.error) raise(*result.error);
    return pair_array(result);
}

py::list collide_many(const Hierarchy& a, const Hierarchy& b, const py::handle& poses_in, bool first) {
    py::ssize_t m = -1;
    const DoubleArray poses = checked_array(poses_in, "poses", {-1, 4, 4}, m);
    const bool round_rotations = narrow_floats(poses_in);
    std::vector<RigidTransform> transforms(static_cast<std::size_t>(m));
    for (py::ssize_t k = 0; k < m; ++k) {
        const double* p = poses.data() + 16 * k;
        if (p[12] != 0.0 || p[13] != 0.0 || p[14] != 0.0 || p[15] != 1.0)
            throw py::value_error("poses[" + std::to_string(k) + "]: the last row of a 4x4 pose must be 0 0 0 1");
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c) transforms[static_cast<std::size_t>(k)].rotation(r, c) = p[4 * r + c];
            transforms[static_cast<std::size_t>(k)].translation(r) = p[4 * r + 3];
        }
        if (round_rotations) transforms[static_cast<std::size_t>(k)].rotation = float32_rotation_repaired(transforms[static_cast<std::size_t>(k)].rotation);
    }
    std::vector<CollideResult> results(transforms.size());
    {
        py::gil_scoped_release unlocked;
        for (std::size_t k = 0; k < transforms.size(); ++k)
            collide(a.tree, RigidTransform::identity(), b.tree, transforms[k], mode_of(first), results[k]);
    }
    py::list out;
    for (std::size_t k = 0; k < results.size(); ++k) {
        if (results[k].error) raise(Error{"poses[" + std::to_string(k) + "]: " + results[k].error->to_string()});
        out.append(pair_array(results[k]));
    }
    return out;
}

}  // namespace
}  // namespace hbvh::python

PYBIND11_MODULE(hbvh, m) {
    using namespace hbvh::python;
    using hbvh::python::Hierarchy;
    using hbvh::python::Primitives;
    m.doc() =
        "hbvh: hybrid bounding volume hierarchies (AABB, OBB, sphere and capsule nodes) for collision detection.\n"
        "Python bindings of the C++ library: hbvh.boxes/spheres/capsules or hbvh.load make primitives,\n"
        "hbvh.build makes a Hierarchy, hbvh.collide / hbvh.collide_many query two posed hierarchies.\n"
        "Bad input raises hbvh.Error (a ValueError) with the message the hbvh CLI prints.";
    m.attr("__version__") = HBVH_VERSION_STRING;
    m.attr("TYPES") = py::make_tuple("aabb", "obb", "sphere", "capsule");

    py::register_exception<BindingError>(m, "Error", PyExc_ValueError).doc() =
        "Bad input (geometry, pose, file, algorithm): the message is hbvh's Error::to_string().";

    py::class_<Primitives>(m, "Primitives", "A list of primitives (the leaves of a hierarchy), in input order.")
        .def(py::init([](const py::handle& parts) { return joined(parts); }), "parts"_a,
             "Joins a list of Primitives in order.")
        .def("__len__", [](const Primitives& p) { return p.items.size(); })
        .def("__add__", [](const Primitives& a, const Primitives& b) { return joined(py::make_tuple(a, b)); })
        .def_property_readonly("array", &primitive_array,
                               "Structured array: type (0 aabb, 1 obb, 2 sphere, 3 capsule), center, rotation "
                               "(3x3, axes as columns), half_extents, radius, p0, p1.")
        .def_property_readonly("names", [](const Primitives& p) {
            py::list names;
            for (const auto& item : p.items) names.append(text_of(item.name));
            return names;
        })
        .def_property_readonly("warnings", [](const Primitives& p) {
            py::list warnings;
            for (const std::string& warning : p.warnings) warnings.append(text_of(warning));
            return warnings;
        }, "What the importer skipped, one line each.")
        .def("__repr__", [](const Primitives& p) { return "<hbvh.Primitives of " + std::to_string(p.items.size()) + ">"; });

    py::class_<Hierarchy>(m, "Hierarchy", "A bounding volume hierarchy with its query layout.")
        .def_property_readonly("cost", [](const Hierarchy& h) { return hbvh::cost(h.bvh); }, "Eq. 2 of the survey.")
        .def("stats", &stats_dict, "The measures of `hbvh stats --json`, as a dict.")
        .def("save", &save, "path"_a,
             "Writes the survey XML, or the binary format for a .hbvh name (atomically). A .hbvh keeps the primitives' "
             "order; XML lists them in the tree's order (its leaves are the primitives), so after load() a pair's "
             "indices refer to that order.")
        .def_property_readonly("nodes", [](const Hierarchy& h) { return node_array(h.bvh); },
                               "Structured array, root first, breadth-first: type (0 aabb, 1 obb, 2 sphere, 3 "
                               "capsule), first_child and child_count (0 for a leaf), primitive (a leaf's input index; "
                               "0, meaning nothing, on inner nodes), center, rotation, half_extents, radius, p0, p1.")
        .def_property_readonly("primitives", [](const Hierarchy& h) { return Primitives{h.bvh.primitives, {}}; })
        .def("__len__", [](const Hierarchy& h) { return h.bvh.nodes.size(); })
        .def("__repr__", [](const Hierarchy& h) {
            return "<hbvh.Hierarchy of " + std::to_string(h.bvh.nodes.size()) + " nodes over " +
                   std::to_string(h.bvh.primitives.size()) + " primitives>";
        });

    m.def("boxes", &make_boxes, "centers"_a, "half_extents"_a, "rotations"_a = py::none(), "names"_a = py::none(),
          "Boxes from (N, 3) centres and half extents; with (N, 3, 3) rotations (axes as columns) OBBs, else AABBs.");
    m.def("spheres", &make_spheres, "centers"_a, "radii"_a, "names"_a = py::none(),
          "Spheres from (N, 3) centres and (N,) radii (or one radius).");
    m.def("capsules", &make_capsules, "p0"_a, "p1"_a, "radii"_a, "names"_a = py::none(),
          "Capsules from (N, 3) segment end points and (N,) radii (or one radius).");
    m.def("load", &load, "path"_a, "format"_a = "", "refit"_a = false,
          "Reads any file the CLI reads (survey XML, MJCF, URDF, meshes, .hbvh): a Hierarchy when the file stores "
          "one, else Primitives. format as the CLI's --format. A stored hierarchy whose volumes miss primitives is "
          "refused, or with refit=True repaired.");
    m.def("build", &build_hierarchy, "primitives"_a, "algorithm"_a = "auto", "types"_a = "aabb,obb,sphere,capsule",
          "time_limit"_a = 0.0, "refine"_a = false, "objective"_a = "eq2", "type_weights"_a = py::none(),
          "Builds a Hierarchy over Primitives (or a list of them) with a registered builder (see algorithms()). "
          "objective as the CLI's --objective: 'eq2' (the survey's Eq. 2) or 'calibrated'; type_weights as its "
          "--type-weight: 'obb=1.3,capsule=1.2', '@FILE' (what `hbvh calibrate -o FILE` wrote) or a dict.");
    m.def("algorithms", [] {
        std::vector<std::string> names;
        for (const hbvh::AlgorithmInfo& info : hbvh::algorithms()) names.emplace_back(info.name);
        return names;
    }, "The registered builders' names, as `hbvh algorithms` lists them.");
    m.def("collide", &collide_pair, "a"_a, "pose_a"_a, "b"_a, "pose_b"_a, "first"_a = false,
          "Overlapping primitive pairs (index in a, index in b) as an (N, 2) int64 array. Poses: 4x4 matrices, "
          "(R, t) tuples or None (identity). first=True stops at the first pair.");
    m.def("collide_many", &collide_many, "a"_a, "b"_a, "poses"_a, "first"_a = false,
          "collide(a, identity, b, poses[k]) for each of the (M, 4, 4) poses, without the GIL: a list of M arrays.");
}
