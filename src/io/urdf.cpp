// SPDX-License-Identifier: MIT
// URDF reader. urdfdom builds the kinematic tree; pugixml runs first for well-formedness errors with lines, for
// the locations of warnings, and for <capsule>, which urdfdom does not know and would reject the model for.
#include "hbvh/io/urdf.hpp"

#include <algorithm>
#include <charconv>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include "hbvh/io/solid_shapes.hpp"
#include "xml_source.hpp"

namespace hbvh {
namespace {

using detail::XmlSource;

// Collects urdfdom's console messages instead of letting them reach stderr (the library never prints).
class CapturingOutput final : public console_bridge::OutputHandler {
public:
    void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
        if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN) messages.push_back(text);
    }
    std::vector<std::string> messages;
};

// console_bridge's handler is process-wide, so imports take turns while it is swapped.
std::mutex console_mutex;

// The capsule extension, read by us because urdfdom rejects unknown geometry.
struct CapsuleShape {
    double radius = 0.0;
    double length = 0.0;  // The cylinder part between the two cap centres (Bullet and Drake convention).
};

// One <collision> element as found in the XML, in document order within its link.
struct CollisionSite {
    pugi::xml_node element;
    std::optional<CapsuleShape> capsule;
};

RigidTransform to_transform(const urdf::Pose& pose) {
    RigidTransform transform;
    transform.translation = Vec3(pose.position.x, pose.position.y, pose.position.z);
    // urdfdom turns rpy into this quaternion with fixed axes, R = Rz(yaw) Ry(pitch) Rx(roll).
    Eigen::Quaterniond q(pose.rotation.w, pose.rotation.x, pose.rotation.y, pose.rotation.z);
    if (q.norm() > 0.0) transform.rotation = q.normalized().toRotationMatrix();
    return transform;
}

// A numeric attribute of a collision, checked here because urdfdom reports any fault in one only as "read a
// different number of collisions": `count` finite numbers (`at_least_zero`: none negative). A valid value is
// written back into `patched` (the same element of the copy urdfdom reads) in a form urdfdom accepts, which
// refuses surrounding blanks that URDF files in the wild have (" 1 ").
struct NumberRule {
    const char* attribute;
    std::size_t count;
    bool at_least_zero;
    bool required;
};

Status check_numbers(const XmlSource& source, const pugi::xml_node& element, pugi::xml_node patched,
                     const NumberRule& rule) {
    const pugi::xml_attribute attribute = element.attribute(rule.attribute);
    const std::string where = "<" + std::string(element.name()) + "> attribute '" + rule.attribute + "'";
    if (!attribute) {
        if (!rule.required) return Ok{};
        return source.error_at(element, where + " is missing");
    }
    const std::optional<std::vector<double>> values = detail::parse_numbers(attribute.value());
    if (!values || values->size() != rule.count)
        return source.error_at(element, where + " needs " + std::to_string(rule.count) + " finite number" +
                                            (rule.count == 1 ? "" : "s") + ", found \"" + attribute.value() + "\"");
    if (rule.at_least_zero && std::any_of(values->begin(), values->end(), [](double v) { return v < 0.0; }))
        return source.error_at(element, where + " must not be negative, found \"" + attribute.value() + "\"");
    std::string canonical;
    for (double v : *values) {
        char text[32];
        const auto [end, code] = std::to_chars(text, text + sizeof text, v);  // shortest form that reads back exactly
        if (!canonical.empty()) canonical += ' ';
        canonical.append(text, end);
    }
    patched.attribute(rule.attribute).set_value(canonical.c_str());
    return Ok{};
}

// An <origin>'s xyz and rpy (each optional), checked and written back as check_numbers does.
Status check_origin(const XmlSource& source, const pugi::xml_node& origin, const pugi::xml_node& patched_origin) {
    if (!origin) return Ok{};
    for (const char* attribute : {"xyz", "rpy"})
        if (Status checked = check_numbers(source, origin, patched_origin, {attribute, 3, false, false}); !checked)
            return checked;
    return Ok{};
}

// The element named `name` (a link or joint) to locate an urdfdom message in the file; null when not found.
pugi::xml_node element_named_in(const pugi::xml_node& robot, const std::string& message) {
    for (const pugi::xml_node& element : robot.children()) {
        const std::string name = element.attribute("name").as_string("");
        if (name.empty()) continue;
        if (message.find("[" + name + "]") != std::string::npos || message.find("'" + name + "'") != std::string::npos)
            return element;
    }
    return {};
}

class UrdfReader {
public:
    explicit UrdfReader(std::string path) : path_(std::move(path)) {}

    Result<ImportResult> run() {
        Result<std::unique_ptr<XmlSource>> loaded = XmlSource::load(path_);
        if (!loaded) return loaded.error();
        source_ = std::move(loaded.value());
        const pugi::xml_node robot = source_->document().document_element();
        if (std::string_view(robot.name()) != "robot")
            return source_->error_at(robot, "root element is <" + std::string(robot.name()) + ">, expected <robot>");

        // Stage 1: find every collision and every capsule; give urdfdom a copy where capsules are cylinders.
        pugi::xml_document patched;
        patched.reset(source_->document());
        if (Status status = scan_collisions(robot, patched.document_element()); !status) return status.error();
        if (Status status = check_joint_origins(robot, patched.document_element()); !status) return status.error();
        std::ostringstream patched_text;
        patched.save(patched_text, "", pugi::format_raw);

        // Stage 2: urdfdom, with its console output captured.
        urdf::ModelInterfaceSharedPtr model;
        CapturingOutput output;
        {
            const std::lock_guard lock(console_mutex);
            console_bridge::useOutputHandler(&output);
            try {
                model = urdf::parseURDF(patched_text.str());
            } catch (const std::exception& exception) {
                output.messages.push_back(exception.what());
            }
            console_bridge::restorePreviousOutputHandler();
        }
        if (!model) {
            std::string message = "urdfdom rejected the model";
            pugi::xml_node where = robot;
            for (std::size_t i = 0; i < output.messages.size(); ++i) {
                message += (i == 0 ? ": " : "; ") + output.messages[i];
                // The first message naming a link or joint locates the problem best.
                if (const pugi::xml_node named = element_named_in(robot, output.messages[i]); named && where == robot)
                    where = named;
            }
            return source_->error_at(where, message);
        }

        // Stage 3: link frames at q = 0, then the collisions of each link in document order.
        for (const pugi::xml_node& link_element : robot.children("link")) {
            const std::string link_name = link_element.attribute("name").as_string("");
            urdf::LinkConstSharedPtr link = model->getLink(link_name);
            if (!link) continue;
            const std::optional<RigidTransform> frame = link_frame(link);
            if (!frame)
                return source_->error_at(link_element,
                                         "link '" + link_name + "' is its own ancestor: its joints form a cycle");
            const RigidTransform& world_from_link = *frame;
            const std::vector<CollisionSite>& sites = collisions_[link_name];
            if (sites.size() != link->collision_array.size()) {
                // urdfdom drops what it cannot parse (a <mesh> without a filename, a scale that is no numbers, and
                // with them the rest of the link) and says why on its console, captured above: pass that on.
                std::string message = "urdfdom read " + std::to_string(link->collision_array.size()) + " of the " +
                                      std::to_string(sites.size()) + " collisions of link '" + link_name + "'";
                for (std::size_t i = 0; i < output.messages.size(); ++i)
                    message += (i == 0 ? ": " : "; ") + output.messages[i];
                return source_->error_at(link_element, message);
            }
            for (std::size_t i = 0; i < sites.size(); ++i) {
                const std::string fallback = link_name + "_collision" + std::to_string(i);
                const std::size_t before = result_.primitives.size();
                if (Status status = add_collision(*link->collision_array[i], sites[i], world_from_link, fallback);
                    !status)
                    return status.error();
                // Sizes near the limit of double, or origins composed along a chain, can overflow.
                if (result_.primitives.size() > before && !detail::is_representable(result_.primitives.back().volume))
                    return source_->error_at(sites[i].element, "collision '" + result_.primitives.back().name +
                                                                   "' is too large: its position or size overflows double");
            }
        }
        return std::move(result_);
    }

private:
    // Records the collisions of each link and replaces each <capsule> in `patched` (a copy of the document with
    // the same structure) by a cylinder urdfdom accepts.
    // Each joint's origin, which places every link below it: checked with its line as a collision's is (urdfdom's
    // own message for a bad one names no line), and handed on in a form urdfdom reads.
    Status check_joint_origins(const pugi::xml_node& robot, const pugi::xml_node& patched_robot) {
        pugi::xml_node patched_joint = patched_robot.child("joint");
        for (const pugi::xml_node& joint : robot.children("joint")) {
            if (Status checked = check_origin(*source_, joint.child("origin"), patched_joint.child("origin")); !checked)
                return checked;
            patched_joint = patched_joint.next_sibling("joint");
        }
        return Ok{};
    }

    Status scan_collisions(const pugi::xml_node& robot, const pugi::xml_node& patched_robot) {
        pugi::xml_node patched_link = patched_robot.child("link");
        for (const pugi::xml_node& link : robot.children("link")) {
            // urdfdom refuses a nameless link as "a different number of collisions" too.
            if (link.attribute("name").as_string()[0] == '\0') return source_->error_at(link, "<link> without a name");
            std::vector<CollisionSite>& sites = collisions_[link.attribute("name").as_string("")];
            pugi::xml_node patched_collision = patched_link.child("collision");
            for (const pugi::xml_node& collision : link.children("collision")) {
                CollisionSite site{collision, std::nullopt};
                // The shape is the geometry's first element (a comment before it is no shape). It holds one; urdfdom
                // reads the first and drops the rest without a word.
                pugi::xml_node shape_element;
                std::size_t shapes = 0;
                for (const pugi::xml_node& child : collision.child("geometry").children()) {
                    if (child.type() != pugi::node_element) continue;
                    if (shapes++ == 0) shape_element = child;
                }
                const std::string_view shape_name = shape_element ? shape_element.name() : "";
                if (shapes > 1)
                    result_.warnings.push_back(source_->warning_at(
                        collision.child("geometry"), "<geometry> holds " + std::to_string(shapes) +
                                                         " shapes; only the first, <" + std::string(shape_name) +
                                                         ">, is read (a URDF geometry has one)"));
                if (shape_name != "box" && shape_name != "sphere" && shape_name != "cylinder" && shape_name != "mesh" &&
                    shape_name != "capsule") {
                    // urdfdom 3 drops such a collision silently; say so, and keep our list in step with its list.
                    result_.warnings.push_back(source_->warning_at(
                        collision, shape_name.empty() ? "collision without geometry skipped"
                                                      : "collision with unknown geometry <" + std::string(shape_name) +
                                                            "> skipped"));
                    const pugi::xml_node next = patched_collision.next_sibling("collision");
                    patched_link.remove_child(patched_collision);
                    patched_collision = next;
                    continue;
                }
                // The collision's numbers, with their lines (a capsule's are read below).
                if (Status checked = check_origin(*source_, collision.child("origin"), patched_collision.child("origin"));
                    !checked)
                    return checked;
                const pugi::xml_node patched_shape = patched_collision.child("geometry").child(shape_element.name());
                std::vector<NumberRule> rules;
                if (shape_name == "box") rules = {{"size", 3, true, true}};
                if (shape_name == "sphere") rules = {{"radius", 1, true, true}};
                if (shape_name == "cylinder") rules = {{"radius", 1, true, true}, {"length", 1, true, true}};
                for (const NumberRule& rule : rules)
                    if (Status checked = check_numbers(*source_, shape_element, patched_shape, rule); !checked)
                        return checked;
                // The first shape only: a <capsule> after another shape is ignored with it (it replaced the first).
                if (shape_name == "capsule") {
                    const pugi::xml_node capsule = shape_element;
                    CapsuleShape shape;
                    for (auto [attribute, slot] : {std::pair{"radius", &shape.radius}, {"length", &shape.length}}) {
                        std::optional<std::vector<double>> value = detail::parse_numbers(capsule.attribute(attribute).value());
                        if (!value || value->size() != 1 || value->front() < 0.0)
                            return source_->error_at(capsule, std::string("capsule ") + attribute +
                                                                  " must be one non-negative number");
                        *slot = value->front();
                    }
                    site.capsule = shape;
                    pugi::xml_node geometry = patched_collision.child("geometry");
                    geometry.remove_child("capsule");
                    pugi::xml_node stand_in = geometry.append_child("cylinder");
                    stand_in.append_attribute("radius").set_value("1");
                    stand_in.append_attribute("length").set_value("1");
                }
                sites.push_back(site);
                patched_collision = patched_collision.next_sibling("collision");
            }
            patched_link = patched_link.next_sibling("link");
        }
        return Ok{};
    }

    // World frame of a link: its parent's frame times the joint origin, memoised (joints at q = 0 add nothing).
    // Empty when the link is its own ancestor: urdfdom 3 accepts a joint whose parent and child are the same link
    // when the model has another root, and the recursion this replaced overflowed the stack (found by fuzz_urdf).
    std::optional<RigidTransform> link_frame(const urdf::LinkConstSharedPtr& link) {
        // Stage 1: up the tree to a link whose frame is known, or to the root.
        std::vector<urdf::LinkConstSharedPtr> chain;
        std::set<std::string> on_chain;
        RigidTransform frame;  // the root's: identity
        for (urdf::LinkConstSharedPtr at = link; at;) {
            if (const auto known = frames_.find(at->name); known != frames_.end()) {
                frame = known->second;
                break;
            }
            if (!on_chain.insert(at->name).second) return std::nullopt;
            chain.push_back(at);
            at = at->parent_joint ? at->getParent() : nullptr;
        }
        // Stage 2: back down, composing each joint's origin.
        for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
            const urdf::LinkConstSharedPtr& child = *it;
            if (child->parent_joint && child->getParent())
                frame = frame * to_transform(child->parent_joint->parent_to_joint_origin_transform);
            frames_[child->name] = frame;
        }
        return frame;
    }

    Status add_collision(const urdf::Collision& collision, const CollisionSite& site, const RigidTransform& world_from_link,
                         const std::string& fallback_name) {
        const std::string name = collision.name.empty() ? fallback_name : collision.name;
        const RigidTransform world = world_from_link * to_transform(collision.origin);
        const pugi::xml_node element = site.element;
        // Only a shape that is a single point is a placeholder (Drake's radius-0 spheres on frame-only links): a
        // plate, a disc or a rod has no volume but real extent, and a flat or thin primitive is valid (until
        // 2026-12-07 any zero size dropped the shape, and a 1 m plate with it).
        auto placeholder = [&](const char* what) {
            result_.warnings.push_back(source_->warning_at(
                element, std::string(what) + " '" + name + "' has zero size (a point); skipped as a placeholder"));
            return Status(Ok{});
        };
        auto negative = [&]() { return Status(source_->error_at(element, "collision '" + name + "' has a negative size")); };
        const Vec3 axis = world.rotation.col(2);
        if (site.capsule) {
            const CapsuleShape& shape = *site.capsule;
            if (shape.radius == 0.0 && shape.length == 0.0) return placeholder("capsule");
            const double half = 0.5 * shape.length;
            result_.primitives.push_back(
                {Capsule{world.translation - half * axis, world.translation + half * axis, shape.radius}, name});
            return Ok{};
        }
        const urdf::GeometrySharedPtr& geometry = collision.geometry;
        switch (geometry->type) {
            case urdf::Geometry::SPHERE: {
                const double radius = static_cast<const urdf::Sphere&>(*geometry).radius;
                if (radius < 0.0) return negative();
                if (radius == 0.0) return placeholder("sphere");
                result_.primitives.push_back({Sphere{world.translation, radius}, name});
                return Ok{};
            }
            case urdf::Geometry::BOX: {
                const urdf::Vector3& dim = static_cast<const urdf::Box&>(*geometry).dim;
                const Vec3 full(dim.x, dim.y, dim.z);
                if ((full.array() < 0.0).any()) return negative();
                if ((full.array() == 0.0).all()) return placeholder("box");
                // URDF gives full extents; hbvh stores half extents.
                result_.primitives.push_back({Obb{world.translation, world.rotation, 0.5 * full}, name});
                return Ok{};
            }
            case urdf::Geometry::CYLINDER: {
                const auto& cylinder = static_cast<const urdf::Cylinder&>(*geometry);
                if (cylinder.radius < 0.0 || cylinder.length < 0.0) return negative();
                if (cylinder.radius == 0.0 && cylinder.length == 0.0) return placeholder("cylinder");
                const double half = 0.5 * cylinder.length;
                if (cylinder.radius == 0.0) {  // a rod: the segment itself, a capsule of radius 0
                    result_.primitives.push_back(
                        {Capsule{world.translation - half * axis, world.translation + half * axis, 0.0}, name});
                    return Ok{};
                }
                // A disc (length 0) comes out as a flat box: its volume 0 beats any capsule's.
                result_.primitives.push_back({enclose_cylinder(world, cylinder.radius, half), name});
                return Ok{};
            }
            case urdf::Geometry::MESH: {
                const std::string& file = static_cast<const urdf::Mesh&>(*geometry).filename;
                result_.warnings.push_back(source_->warning_at(
                    element, "mesh collision '" + name + "' (" + file + ") skipped: the URDF importer reads primitives only"));
                return Ok{};
            }
        }
        return source_->error_at(element, "collision '" + name + "' has an unknown geometry type");
    }

    std::string path_;
    std::unique_ptr<XmlSource> source_;
    std::map<std::string, std::vector<CollisionSite>> collisions_;
    std::map<std::string, RigidTransform> frames_;
    ImportResult result_;
};

}  // namespace

Result<ImportResult> import_urdf(const std::string& path) { return UrdfReader(path).run(); }

}  // namespace hbvh
