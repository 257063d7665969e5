// SPDX-License-Identifier: MIT
// MJCF reader: walks the XML with pugixml instead of compiling it with MuJoCo, because real files use attributes
// newer than any installed MuJoCo and reference mesh files that are often missing. The semantics follow the MJCF
// reference (default classes, frame composition, orientation conventions); tests check them against MuJoCo.
#include "hbvh/io/mjcf.hpp"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <numbers>
#include <span>

#include "hbvh/io/solid_shapes.hpp"
#include "mjcf_orientation.hpp"
#include "xml_source.hpp"

namespace hbvh {
namespace {

using detail::XmlSource;

constexpr int max_include_depth = 32;
// Deeper body or default trees than this are not real models; refusing them keeps the recursion off the stack limit.
constexpr int max_tree_depth = 1000;

// An attribute value found on an element or in a default class, with the element it came from (for errors).
struct FoundAttribute {
    const char* value = nullptr;
    pugi::xml_node element;
};

// One <default class> level: its parent class and its <geom> defaults, later ones overriding earlier ones
// (several top-level <default> elements, e.g. from includes, all add to class "main").
struct DefaultClass {
    std::string parent;
    std::vector<pugi::xml_node> geoms;
};

struct CompilerSettings {
    bool degrees = true;  // MJCF's default unit for euler and axisangle.
    std::string euler_sequence = "xyz";
};

class MjcfReader {
public:
    explicit MjcfReader(std::string path) : main_path_(std::move(path)) {}

    Result<ImportResult> run() {
        Result<std::unique_ptr<XmlSource>> main = XmlSource::load(main_path_);
        if (!main) return main.error();
        sources_.push_back(std::move(main.value()));
        const XmlSource& source = *sources_.front();
        const pugi::xml_node root = source.document().document_element();
        if (std::string_view(root.name()) != "mujoco")
            return source.error_at(root, "root element is <" + std::string(root.name()) + ">, expected <mujoco>");
        base_directory_ = std::filesystem::path(main_path_).parent_path();
        included_files_[file_key(main_path_)] = "as the main file";

        // Stage 1: compiler settings and default classes apply wherever they appear, so read them first.
        if (Status status = for_each_child(root, [&](pugi::xml_node child) { return read_top_level(child); });
            !status)
            return status.error();
        // Stage 2: the body tree. Several <worldbody> elements (e.g. from includes) form one world body, as in MuJoCo.
        std::vector<pugi::xml_node> world_parts;
        if (Status status = for_each_child(root, [&](pugi::xml_node child) -> Status {
                if (std::string_view(child.name()) == "worldbody") world_parts.push_back(child);
                return Ok{};
            });
            !status)
            return status.error();
        if (world_parts.empty()) {
            result_.warnings.push_back(source.warning_at(root, "no <worldbody>: the model has no geometry"));
            return std::move(result_);
        }
        if (Status status = read_body(world_parts, RigidTransform::identity(), "", true); !status) return status.error();
        return std::move(result_);
    }

private:
    // Visits the element children of `parent` in order, replacing each <include file="..."> by the children of
    // the included file's <mujoco> root (MuJoCo resolves include paths against the main file's folder).
    Status for_each_child(const pugi::xml_node& parent, const std::function<Status(pugi::xml_node)>& visit,
                          int depth = 0) {
        for (pugi::xml_node child = parent.first_child(); child; child = child.next_sibling()) {
            if (child.type() != pugi::node_element) continue;
            if (std::string_view(child.name()) != "include") {
                if (Status status = visit(child); !status) return status;
                continue;
            }
            // Each pass over the model (defaults, then bodies) meets the same <include>: it is read on the first.
            const XmlSource* loaded_before = nullptr;
            if (const auto found = expanded_.find(child.internal_object()); found != expanded_.end())
                loaded_before = found->second;
            if (loaded_before == nullptr) {
                Result<const XmlSource*> loaded = load_include(child, depth);
                if (!loaded) return loaded.error();
                loaded_before = *loaded;
            }
            const XmlSource& inner = *loaded_before;
            const pugi::xml_node inner_root = inner.document().document_element();
            if (std::string_view(inner_root.name()) != "mujoco")
                return inner.error_at(inner_root, "an included file must have the root element <mujoco>");
            if (Status status = for_each_child(inner_root, visit, depth + 1); !status) return status;
        }
        return Ok{};
    }

    // Reads the file an <include> names, once per model: MuJoCo refuses a file included twice, and without that
    // rule 17 small files that each include the next one twice expanded 2^16 times (minutes, gigabytes).
    Result<const XmlSource*> load_include(const pugi::xml_node& include, int depth) {
        const XmlSource& here = source_of(include);
        const char* file = include.attribute("file").as_string(nullptr);
        if (file == nullptr || *file == '\0') return here.error_at(include, "<include> without a file attribute");
        if (depth >= max_include_depth) return here.error_at(include, "includes nested too deeply (a cycle?)");
        std::filesystem::path included = file;
        if (included.is_relative()) included = base_directory_ / included;
        // The name comes from the file, so it may be /dev/zero, /dev/stdin or a FIFO, which would never end.
        std::error_code ignored;
        if (std::filesystem::exists(included, ignored) && !std::filesystem::is_regular_file(included, ignored))
            return here.error_at(include, "cannot include '" + std::string(file) + "': not a regular file");
        const std::string key = file_key(included);
        if (const auto seen = included_files_.find(key); seen != included_files_.end())
            return here.error_at(include, "'" + std::string(file) + "' is included a second time (first " +
                                              seen->second + "); MuJoCo includes a file once");
        Result<std::unique_ptr<XmlSource>> loaded = XmlSource::load(included.string());
        if (!loaded) {
            // Report where the include is, and why the included file failed.
            return here.error_at(include, "cannot include '" + std::string(file) + "': " + loaded.error().to_string());
        }
        included_files_[key] = "at " + here.path() + ":" + std::to_string(here.line_of(include));
        sources_.push_back(std::move(loaded.value()));
        expanded_[include.internal_object()] = sources_.back().get();
        return sources_.back().get();
    }

    // The same key for every name of one file (relative, with .., through links), where it can be resolved.
    static std::string file_key(const std::filesystem::path& path) {
        std::error_code error;
        const std::filesystem::path resolved = std::filesystem::weakly_canonical(path, error);
        return (error ? path.lexically_normal() : resolved).string();
    }

    // The file a node was parsed from (the main file or one of the includes).
    const XmlSource& source_of(const pugi::xml_node& node) const {
        const pugi::xml_node document = node.root();
        for (const auto& source : sources_)
            if (source->document() == document) return *source;
        return *sources_.front();
    }
    Error error_at(const pugi::xml_node& node, const std::string& message) const {
        return source_of(node).error_at(node, message);
    }
    void warn(const pugi::xml_node& node, const std::string& message) {
        result_.warnings.push_back(source_of(node).warning_at(node, message));
    }

    Status read_top_level(const pugi::xml_node& element) {
        const std::string_view name = element.name();
        if (name == "compiler") return read_compiler(element);
        if (name == "default") return read_default(element, "");
        return Ok{};
    }

    Status read_compiler(const pugi::xml_node& element) {
        if (const pugi::xml_attribute angle = element.attribute("angle")) {
            const std::string_view unit = angle.value();
            if (unit != "degree" && unit != "radian")
                return error_at(element, "compiler angle must be 'degree' or 'radian', not '" + std::string(unit) + "'");
            compiler_.degrees = unit == "degree";
        }
        if (const pugi::xml_attribute sequence = element.attribute("eulerseq")) {
            const std::string_view text = sequence.value();
            if (text.size() != 3 || text.find_first_not_of("xyzXYZ") != std::string_view::npos)
                return error_at(element, "compiler eulerseq must be 3 of xyzXYZ, not '" + std::string(text) + "'");
            compiler_.euler_sequence = text;
        }
        // Global coordinates (removed in MuJoCo 2.3.3) would need a different composition rule for every frame.
        if (std::string_view(element.attribute("coordinate").as_string("local")) == "global")
            return error_at(element, "compiler coordinate=\"global\" is not supported; convert the model to local");
        return Ok{};
    }

    // Registers a <default> element and its nested classes. The top-level one is class "main".
    Status read_default(const pugi::xml_node& element, const std::string& parent, int depth = 0) {
        const bool top_level = parent.empty();
        if (depth > max_tree_depth) return error_at(element, "<default> classes nested too deeply");
        std::string name = top_level ? "main" : element.attribute("class").as_string("");
        if (name.empty()) return error_at(element, "nested <default> without a class attribute");
        if (classes_.contains(name) && !top_level)
            return error_at(element, "default class '" + name + "' is defined twice");
        classes_[name].parent = parent;
        // The top-level <default> is the root class whatever its class attribute says (MuJoCo applies it to every
        // geom without a class); a name it gives is one more way to refer to it: a class of its own with no
        // defaults, below main.
        if (const std::string alias = element.attribute("class").as_string("main"); top_level && alias != "main") {
            if (classes_.contains(alias) && classes_[alias].parent != "main")
                return error_at(element, "default class '" + alias + "' is defined twice");
            classes_[alias].parent = "main";
        }
        return for_each_child(element, [&](pugi::xml_node child) -> Status {
            const std::string_view child_name = child.name();
            if (child_name == "default") return read_default(child, name, depth + 1);
            if (child_name == "geom") classes_[name].geoms.push_back(child);
            return Ok{};
        });
    }

    // The class chain of a geom, most specific first. Error for a class that no <default> defines.
    Result<std::vector<const DefaultClass*>> class_chain(const pugi::xml_node& geom, const std::string& class_name) {
        std::vector<const DefaultClass*> chain;
        std::string current = class_name;
        while (!current.empty()) {
            const auto found = classes_.find(current);
            if (found == classes_.end()) {
                // Only "main" may be absent: a model without <default> has an empty main class.
                if (current == "main") break;
                return error_at(geom, "unknown default class '" + current + "'");
            }
            chain.push_back(&found->second);
            if (chain.size() > classes_.size()) return error_at(geom, "default classes form a cycle");
            current = found->second.parent;
        }
        return chain;
    }

    static FoundAttribute find_attribute(const pugi::xml_node& geom, const std::vector<const DefaultClass*>& chain,
                                         const char* name) {
        if (const pugi::xml_attribute own = geom.attribute(name)) return {own.value(), geom};
        for (const DefaultClass* level : chain)
            for (auto geom_default = level->geoms.rbegin(); geom_default != level->geoms.rend(); ++geom_default)
                if (const pugi::xml_attribute inherited = geom_default->attribute(name))
                    return {inherited.value(), *geom_default};
        return {};
    }

    // The element, then every <geom> default of its class chain, most specific first.
    static std::vector<pugi::xml_node> levels_of(const pugi::xml_node& element,
                                                 const std::vector<const DefaultClass*>& chain) {
        std::vector<pugi::xml_node> levels{element};
        for (const DefaultClass* level : chain) levels.insert(levels.end(), level->geoms.rbegin(), level->geoms.rend());
        return levels;
    }

    // Parses exactly `count` numbers (or between `count` and `max_count`) from an attribute.
    Result<std::vector<double>> numbers(const FoundAttribute& found, const char* name, std::size_t count,
                                        std::size_t max_count = 0) const {
        std::optional<std::vector<double>> values = detail::parse_numbers(found.value);
        const std::size_t upper = max_count == 0 ? count : max_count;
        if (!values || values->size() < count || values->size() > upper) {
            const std::string expected = max_count == 0 ? std::to_string(count)
                                                        : std::to_string(count) + " to " + std::to_string(upper);
            return error_at(found.element, std::string("attribute ") + name + "=\"" + found.value + "\" must hold " +
                                               expected + " finite numbers");
        }
        return std::move(*values);
    }

    double to_radians(double angle) const { return compiler_.degrees ? angle * std::numbers::pi / 180.0 : angle; }

    // Reads the orientation of an element: the most specific level that gives any of the five forms wins whole,
    // so a geom's own quat replaces a class's euler. Recent MuJoCo sources do the same; MuJoCo 2.2.2 instead
    // lets a class's euler/axisangle/xyaxes/zaxis beat the geom's own quat (see docs/importers.md).
    Result<Mat3> orientation(const pugi::xml_node& element, const std::vector<const DefaultClass*>& chain) {
        static constexpr std::array<const char*, 5> forms{"quat", "axisangle", "xyaxes", "zaxis", "euler"};
        const std::vector<pugi::xml_node> levels = levels_of(element, chain);
        for (const pugi::xml_node& level : levels) {
            const char* form = nullptr;
            for (const char* candidate : forms) {
                if (!level.attribute(candidate)) continue;
                if (form != nullptr)
                    return error_at(level, std::string("both ") + form + " and " + candidate +
                                               " given; use one orientation attribute");
                form = candidate;
            }
            if (form == nullptr) continue;
            const FoundAttribute found{level.attribute(form).value(), level};
            const std::string_view kind = form;
            std::optional<Mat3> rotation;
            if (kind == "quat") {
                Result<std::vector<double>> q = numbers(found, form, 4);
                if (!q) return q.error();
                rotation = detail::rotation_from_quat((*q)[0], (*q)[1], (*q)[2], (*q)[3]);
            } else if (kind == "axisangle") {
                Result<std::vector<double>> a = numbers(found, form, 4);
                if (!a) return a.error();
                rotation = detail::rotation_from_axis_angle(Vec3((*a)[0], (*a)[1], (*a)[2]), to_radians((*a)[3]));
            } else if (kind == "xyaxes") {
                Result<std::vector<double>> a = numbers(found, form, 6);
                if (!a) return a.error();
                rotation = detail::rotation_from_xy_axes(Vec3((*a)[0], (*a)[1], (*a)[2]), Vec3((*a)[3], (*a)[4], (*a)[5]));
            } else if (kind == "zaxis") {
                Result<std::vector<double>> a = numbers(found, form, 3);
                if (!a) return a.error();
                rotation = detail::rotation_from_z_axis(Vec3((*a)[0], (*a)[1], (*a)[2]));
            } else {
                Result<std::vector<double>> a = numbers(found, form, 3);
                if (!a) return a.error();
                rotation = detail::rotation_from_euler(
                    Vec3(to_radians((*a)[0]), to_radians((*a)[1]), to_radians((*a)[2])), compiler_.euler_sequence);
            }
            if (!rotation) return error_at(level, std::string("degenerate ") + form + "=\"" + found.value + "\"");
            return *rotation;
        }
        return Mat3(Mat3::Identity());
    }

    // Warns of each attribute of `element` that `known` does not list: MuJoCo refuses them, and a misspelt
    // `eular` or `poss` would otherwise leave the element unturned or at the origin without a word.
    void warn_unknown_attributes(const pugi::xml_node& element, std::span<const std::string_view> known) {
        for (const pugi::xml_attribute& attribute : element.attributes())
            if (std::find(known.begin(), known.end(), std::string_view(attribute.name())) == known.end())
                warn(element, "unknown attribute '" + std::string(attribute.name()) + "' of <" +
                                  std::string(element.name()) + "> ignored");
    }

    // The local frame of a body or frame element: its own pos and orientation (bodies take no defaults).
    Result<RigidTransform> own_frame(const pugi::xml_node& element) {
        // Every attribute of <body> and <frame> in MuJoCo 2.2-3.x.
        static constexpr std::array<std::string_view, 14> known{
            "name", "childclass", "pos", "quat", "axisangle", "xyaxes", "zaxis", "euler", "mocap", "gravcomp", "user",
            "sleep", "class", "frame"};
        warn_unknown_attributes(element, known);
        RigidTransform frame;
        if (const pugi::xml_attribute pos = element.attribute("pos")) {
            Result<std::vector<double>> p = numbers({pos.value(), element}, "pos", 3);
            if (!p) return p.error();
            frame.translation = Vec3((*p)[0], (*p)[1], (*p)[2]);
        }
        Result<Mat3> rotation = orientation(element, {});
        if (!rotation) return rotation.error();
        frame.rotation = *rotation;
        return frame;
    }

    // One body: its geoms first (including those inside <frame>s), then its child bodies, which reproduces
    // MuJoCo's geom order (bodies in depth-first order, geoms in document order within a body).
    // `parts` is one <body>, or every <worldbody> of the model for the world body.
    Status read_body(const std::vector<pugi::xml_node>& parts, const RigidTransform& world_from_parent,
                     std::string child_class, bool is_world, int depth = 0) {
        const pugi::xml_node body = parts.front();
        if (depth > max_tree_depth) return error_at(body, "bodies nested too deeply");
        RigidTransform world_from_body = world_from_parent;
        std::string body_name = "world";
        const int body_id = body_count_++;
        if (!is_world) {
            Result<RigidTransform> local = own_frame(body);
            if (!local) return local.error();
            world_from_body = world_from_parent * *local;
            body_name = body.attribute("name").as_string("");
            if (body_name.empty()) body_name = "body" + std::to_string(body_id);
            if (const pugi::xml_attribute cls = body.attribute("childclass")) child_class = cls.value();
        }
        struct PendingBody {
            pugi::xml_node node;
            RigidTransform world_from_parent;
            std::string child_class;
        };
        std::vector<PendingBody> children;
        int geom_index = 0;
        int frame_depth = 0;
        // Walks body content; <frame> only adds a transform (and possibly a childclass) for what it contains.
        std::function<Status(const pugi::xml_node&, const RigidTransform&, const std::string&)> walk =
            [&](const pugi::xml_node& container, const RigidTransform& world_from_container,
                const std::string& container_class) -> Status {
            return for_each_child(container, [&](pugi::xml_node child) -> Status {
                const std::string_view name = child.name();
                if (name == "geom") {
                    const std::string fallback = body_name + "_geom" + std::to_string(geom_index++);
                    return read_geom(child, world_from_container, container_class, fallback);
                }
                if (name == "body") {
                    children.push_back({child, world_from_container, container_class});
                    return Ok{};
                }
                if (name == "frame") {
                    Result<RigidTransform> local = own_frame(child);
                    if (!local) return local.error();
                    const std::string frame_class = child.attribute("childclass").as_string(container_class.c_str());
                    if (++frame_depth > max_tree_depth) return error_at(child, "frames nested too deeply");
                    Status status = walk(child, world_from_container * *local, frame_class);
                    --frame_depth;
                    return status;
                }
                if (name == "composite" || name == "flexcomp" || name == "replicate" || name == "attach") {
                    warn(child, "<" + std::string(name) + "> skipped: generated geometry is not supported");
                    return Ok{};
                }
                // MuJoCo refuses an element its schema does not know; a misspelt <bdoy> would lose its geoms here
                // without a word.
                static constexpr std::array<std::string_view, 7> without_geometry{
                    "inertial", "joint", "freejoint", "site", "camera", "light", "plugin"};
                if (std::find(without_geometry.begin(), without_geometry.end(), name) == without_geometry.end())
                    warn(child, "unknown element <" + std::string(name) + "> in a body skipped, with whatever it holds");
                return Ok{};
            });
        };
        for (const pugi::xml_node& part : parts)
            if (Status status = walk(part, world_from_body, child_class); !status) return status;
        for (const PendingBody& child : children)
            if (Status status = read_body({child.node}, child.world_from_parent, child.child_class, false, depth + 1);
                !status)
                return status;
        return Ok{};
    }

    Status read_geom(const pugi::xml_node& geom, const RigidTransform& world_from_body, const std::string& child_class,
                     const std::string& fallback_name) {
        const std::string class_name = geom.attribute("class").as_string(child_class.empty() ? "main" : child_class.c_str());
        Result<std::vector<const DefaultClass*>> chain_result = class_chain(geom, class_name);
        if (!chain_result) return chain_result.error();
        const std::vector<const DefaultClass*>& chain = *chain_result;
        const std::string name = geom.attribute("name").as_string(fallback_name.c_str());
        // Every attribute of <geom> in MuJoCo 2.2-3.x.
        static constexpr std::array<std::string_view, 34> known{
            "name",     "class",    "type",        "contype",   "conaffinity", "condim",     "group",
            "priority", "size",     "material",    "friction",  "mass",        "density",    "shellinertia",
            "solmix",   "solref",   "solimp",      "margin",    "gap",         "fromto",     "pos",
            "quat",     "axisangle", "xyaxes",     "zaxis",     "euler",       "hfield",     "mesh",
            "fitscale", "rgba",     "fluidshape",  "fluidcoef", "user",        "plugin"};
        warn_unknown_attributes(geom, known);

        // Stage 1: is this collision geometry at all?
        const FoundAttribute type_attribute = find_attribute(geom, chain, "type");
        const std::string type = type_attribute.value != nullptr ? type_attribute.value : "sphere";
        if (type == "plane" || type == "hfield") return Ok{};  // Floors and terrain are not object primitives.
        // A collision bit mask: one whole number, blanks around it and a decimal point allowed ("1 ", "1.0"),
        // as MuJoCo 2.2.2 reads it.
        bool collides = false;
        for (const char* flag : {"contype", "conaffinity"}) {
            const FoundAttribute found = find_attribute(geom, chain, flag);
            if (found.value == nullptr) {
                collides = true;  // both default to 1
                continue;
            }
            const std::optional<std::vector<double>> value = detail::parse_numbers(found.value);
            if (!value || value->size() != 1 || std::trunc(value->front()) != value->front() ||
                std::abs(value->front()) > 2147483647.0)
                return error_at(found.element, std::string(flag) + "=\"" + found.value + "\" is not an integer");
            collides = collides || value->front() != 0.0;
        }
        if (!collides) return Ok{};
        if (type == "mesh" || type == "sdf") {
            warn(geom, type + " geom '" + name + "' skipped: the MJCF importer reads primitives only");
            return Ok{};
        }
        if (type != "sphere" && type != "capsule" && type != "cylinder" && type != "box" && type != "ellipsoid")
            return error_at(geom, "unknown geom type '" + type + "'");
        if (find_attribute(geom, chain, "mesh").value != nullptr) {
            // MuJoCo would size this primitive to fit the mesh, which needs the mesh file.
            warn(geom, type + " geom '" + name + "' skipped: it is fitted to a mesh, and meshes are not read");
            return Ok{};
        }

        // Stage 2: size (half sizes; trailing unused values are allowed).
        // MuJoCo overwrites only the components a level gives, so size="0.08" in a class keeps its parent's
        // half-length: overlay the levels from the root class down to the geom.
        std::array<double, 3> size{0.0, 0.0, 0.0};
        const std::vector<pugi::xml_node> size_levels = levels_of(geom, chain);
        for (auto level = size_levels.rbegin(); level != size_levels.rend(); ++level) {
            const pugi::xml_attribute attribute = level->attribute("size");
            if (!attribute) continue;
            Result<std::vector<double>> values = numbers({attribute.value(), *level}, "size", 1, 3);
            if (!values) return values.error();
            for (std::size_t i = 0; i < values->size(); ++i) size[i] = (*values)[i];
        }

        // Stage 3: the frame, from fromto (which overrides pos and orientation) or from pos + orientation.
        RigidTransform local;
        const FoundAttribute fromto = find_attribute(geom, chain, "fromto");
        // MuJoCo refuses a sphere with fromto (from its class too): it has no axis to lay along the segment.
        if (fromto.value != nullptr && type == "sphere")
            return error_at(fromto.element, "fromto needs a capsule, cylinder, box or ellipsoid, not a sphere (as in MuJoCo)");
        const bool uses_fromto = fromto.value != nullptr;
        if (uses_fromto) {
            Result<std::vector<double>> ends = numbers(fromto, "fromto", 6);
            if (!ends) return ends.error();
            // fromto sets the centre, so a pos beside it (the geom's or its class's) would be dropped without a
            // word; MuJoCo 2.2.2 refuses a non-zero one ("both pos and fromto defined"), whichever level gives
            // either, and so do we.
            if (const FoundAttribute pos = find_attribute(geom, chain, "pos"); pos.value != nullptr) {
                Result<std::vector<double>> p = numbers(pos, "pos", 3);
                if (!p) return p.error();
                if ((*p)[0] != 0.0 || (*p)[1] != 0.0 || (*p)[2] != 0.0) {
                    const XmlSource& where = source_of(fromto.element);
                    return error_at(pos.element, "pos and fromto (at " + where.path() + ":" +
                                                     std::to_string(where.line_of(fromto.element)) +
                                                     ") are both given; fromto sets the centre, and MuJoCo refuses "
                                                     "the pair: drop pos, or move the segment");
                }
            }
            const Vec3 from((*ends)[0], (*ends)[1], (*ends)[2]);
            const Vec3 to((*ends)[3], (*ends)[4], (*ends)[5]);
            // MuJoCo turns z onto from - to (checked against mj_forward of 2.2.2): a box's or ellipsoid's x and y
            // axes depend on that sign unless the segment lies on a world axis.
            std::optional<Mat3> rotation = detail::rotation_from_z_axis(from - to);
            if (!rotation) return error_at(fromto.element, "fromto end points coincide");
            local.rotation = *rotation;
            local.translation = 0.5 * (from + to);
            // The half-length slot is size[1] for capsules and cylinders, size[2] for boxes and ellipsoids; MuJoCo
            // (checked with 2.2.2) then gives boxes and ellipsoids a square/round cross-section of size[0].
            if (type == "capsule" || type == "cylinder") {
                size[1] = 0.5 * (to - from).norm();
            } else {
                size[1] = size[0];
                size[2] = 0.5 * (to - from).norm();
            }
        } else {
            if (const FoundAttribute pos = find_attribute(geom, chain, "pos"); pos.value != nullptr) {
                Result<std::vector<double>> p = numbers(pos, "pos", 3);
                if (!p) return p.error();
                local.translation = Vec3((*p)[0], (*p)[1], (*p)[2]);
            }
            Result<Mat3> rotation = orientation(geom, chain);
            if (!rotation) return rotation.error();
            local.rotation = *rotation;
        }
        const RigidTransform world = world_from_body * local;

        // Stage 4: the bounding volume of the shape.
        const std::size_t needed = type == "sphere" ? 1 : (type == "capsule" || type == "cylinder") ? 2 : 3;
        for (std::size_t i = 0; i < needed; ++i)
            if (!(size[i] > 0.0))
                return error_at(geom, type + " geom '" + name + "' needs " + std::to_string(needed) +
                                          " positive size values (half sizes)");
        BoundingVolume volume;
        const Vec3 axis = world.rotation.col(2);
        if (type == "sphere") {
            volume = Sphere{world.translation, size[0]};
        } else if (type == "capsule") {
            volume = Capsule{world.translation - size[1] * axis, world.translation + size[1] * axis, size[0]};
        } else if (type == "box") {
            volume = Obb{world.translation, world.rotation, Vec3(size[0], size[1], size[2])};
        } else if (type == "cylinder") {
            volume = enclose_cylinder(world, size[0], size[1]);
        } else {
            volume = enclose_ellipsoid(world, Vec3(size[0], size[1], size[2]));
        }
        if (!detail::is_representable(volume))
            return error_at(geom, type + " geom '" + name + "' is too large: its position or size overflows double");
        result_.primitives.push_back({std::move(volume), name});
        return Ok{};
    }

    std::string main_path_;
    std::filesystem::path base_directory_;
    std::vector<std::unique_ptr<XmlSource>> sources_;
    std::map<pugi::xml_node_struct*, const XmlSource*> expanded_;  ///< Each <include> read, and its file.
    std::map<std::string, std::string> included_files_;          ///< file_key of each file read -> where: "at file:line" of its <include>, or "as the main file"
    std::map<std::string, DefaultClass> classes_;
    CompilerSettings compiler_;
    ImportResult result_;
    int body_count_ = 0;
};

}  // namespace

Result<ImportResult> import_mjcf(const std::string& path) { return MjcfReader(path).run(); }

}  // namespace hbvh
