// SPDX-License-Identifier: MIT
// `hbvh collide`: do two posed objects touch, and which primitive pairs overlap.
#include <fmt/core.h>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <charconv>
#include <iterator>
#include <cmath>
#include <optional>
#include <sstream>
#include <string_view>

#include "commands/command.hpp"
#include "hbvh/geometry/validation.hpp"
#include "hbvh/query/tandem_traversal.hpp"

namespace hbvh::cli {
namespace {
struct CollideArguments {
    std::string input_a;
    std::string input_b;
    std::string format;  ///< --format, for both inputs.
    std::optional<std::string> pose_a;  ///< Absent: the identity. Given, even empty, it must parse.
    std::optional<std::string> pose_b;
    BuilderFlags builder;
    bool first = false;
    bool json = false;
    bool names = false;  ///< --names: each pair's primitive names too.
};

/// A name as a JSON string (quoted, escaped; bytes that are no UTF-8 as U+FFFD, as the writers do).
std::string json_quoted(const std::string& name) {
    return nlohmann::json(name).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

/// "tx ty tz [qw qx qy qz]": a translation and an optional rotation quaternion (normalised).
Result<RigidTransform> parse_pose(const std::string& text, const char* flag) {
    std::istringstream stream(text);
    std::vector<double> numbers;
    std::string word;
    while (stream >> word) {
        // from_chars, as the XML reader parses numbers: decimal only (no hex, no locale), and a value too small
        // for a double reads as out of range rather than failing as "not a number".
        // A leading '+', which from_chars refuses, is accepted as the XML reader accepts it (not before a sign).
        std::string_view digits = word;
        if (digits.size() > 1 && digits.front() == '+' && digits[1] != '+' && digits[1] != '-') digits.remove_prefix(1);
        double value = 0.0;
        const auto [end, code] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
        if (code == std::errc::result_out_of_range)
            return Error{std::string(flag) + ": '" + word + "' is out of the range of double"};
        if (code != std::errc{} || end != digits.data() + digits.size() || !std::isfinite(value))
            return Error{std::string(flag) + ": '" + word + "' is not a finite number"};
        numbers.push_back(value);
    }
    if (numbers.size() != 3 && numbers.size() != 7)
        return Error{std::string(flag) + " needs 3 numbers (translation) or 7 (translation, then quaternion w x y z)"};
    const Vec3 translation(numbers[0], numbers[1], numbers[2]);
    if (numbers.size() == 3) return RigidTransform{Mat3::Identity(), translation};
    // The quaternion's scale does not matter (it is normalised): bring it near 1 first, so that 1e300 and 1e-300
    // components neither overflow nor vanish in the norm.
    Eigen::Vector4d quaternion(numbers[3], numbers[4], numbers[5], numbers[6]);
    const double largest = quaternion.cwiseAbs().maxCoeff();
    if (!(largest > 0.0)) return Error{std::string(flag) + ": the quaternion is zero"};
    quaternion /= largest;
    if (quaternion.norm() < 1e-12) return Error{std::string(flag) + ": the quaternion is zero"};
    numbers[3] = quaternion[0], numbers[4] = quaternion[1], numbers[5] = quaternion[2], numbers[6] = quaternion[3];
    const RigidTransform pose = RigidTransform::from_quaternion(numbers[3], numbers[4], numbers[5], numbers[6], translation);
    if (std::string problem = pose_problem(pose); !problem.empty()) return Error{std::string(flag) + ": " + problem};
    return pose;
}

int run_collide(const CollideArguments& args) {
    const std::optional<BuildRequest> request = resolve_or_report(args.builder, "collide");
    if (!request) return exit_bad_usage;
    Result<RigidTransform> pose_a = args.pose_a ? parse_pose(*args.pose_a, "--pose-a") : Result<RigidTransform>(RigidTransform{});
    Result<RigidTransform> pose_b = args.pose_b ? parse_pose(*args.pose_b, "--pose-b") : Result<RigidTransform>(RigidTransform{});
    for (const Result<RigidTransform>* pose : {&pose_a, &pose_b})
        if (!*pose) {
            fmt::print(stderr, "hbvh collide: {}\n", pose->error().to_string());
            return exit_bad_usage;
        }
    Result<Model> model_a = load_model(args.input_a, args.format);
    if (!model_a) return report_error(model_a.error());
    report_warnings(model_a->warnings);
    Result<Model> model_b = load_model(args.input_b, args.format);
    if (!model_b) return report_error(model_b.error());
    report_warnings(model_b->warnings);
    Result<Bvh> bvh_a = hierarchy_of(model_a.value(), *request, args.builder);
    if (!bvh_a) return report_error(bvh_a.error());
    Result<Bvh> bvh_b = hierarchy_of(model_b.value(), *request, args.builder);
    if (!bvh_b) return report_error(bvh_b.error());

    const CollideResult result = collide(bvh_a.value(), pose_a.value(), bvh_b.value(), pose_b.value(),
                                         args.first ? CollideMode::first : CollideMode::all);
    if (result.error) return report_error(*result.error);
    if (args.json) {
        // Written as it goes, as nlohmann::json's own one-line dump would write it: a DOM of every pair took 2.9 GB
        // for 9 million pairs (3 000 coincident spheres), and running out of memory inside the library's noexcept
        // code ended in std::terminate instead of the "out of memory" message.
        std::string text = fmt::format("{{\"intersecting\":{},\"pairs\":[", result.intersecting);
        for (std::size_t k = 0; k < result.pairs.size(); ++k) {
            fmt::format_to(std::back_inserter(text), "{}[{},{}]", k == 0 ? "" : ",", result.pairs[k].first,
                           result.pairs[k].second);
            if (text.size() >= (std::size_t{1} << 20)) fmt::print("{}", text), text.clear();
        }
        text += ']';
        if (args.names) {
            // Names are what stays put across formats: survey XML lists primitives in tree order, so the same
            // model read from its source and from a built XML numbers them differently.
            text += ",\"names\":[";
            for (std::size_t k = 0; k < result.pairs.size(); ++k) {
                const auto [i, j] = result.pairs[k];
                fmt::format_to(std::back_inserter(text), "{}[{},{}]", k == 0 ? "" : ",",
                               json_quoted(bvh_a->primitives[i].name), json_quoted(bvh_b->primitives[j].name));
                if (text.size() >= (std::size_t{1} << 20)) fmt::print("{}", text), text.clear();
            }
            text += ']';
        }
        fmt::print("{},\"bv_tests\":{},\"primitive_tests\":{}}}\n", text, result.bv_tests, result.primitive_tests);
    } else {
        fmt::print("{}\n", result.intersecting ? "intersecting" : "separate");
        for (const auto& [i, j] : result.pairs) {
            if (args.names)
                fmt::print("  {} {} {} {}\n", i, j, json_quoted(bvh_a->primitives[i].name), json_quoted(bvh_b->primitives[j].name));
            else
                fmt::print("  {} {}\n", i, j);
        }
        fmt::print("bv tests {}, primitive tests {}, nodes visited {}\n", result.bv_tests, result.primitive_tests,
                   result.nodes_visited);
    }
    return exit_ok;
}
}  // namespace

void add_collide_command(CLI::App& app, Command& command) {
    auto args = std::make_shared<CollideArguments>();
    CLI::App* sub = app.add_subcommand("collide", "Test two posed objects for contact (tandem traversal)");
    sub->add_option("a", args->input_a, "First object: a hierarchy or a primitive set")->required();
    sub->add_option("b", args->input_b, "Second object")->required();
    sub->add_option("--format", args->format, "Input format of both objects when their extensions do not tell")
        ->check(input_format());
    sub->add_option("--pose-a", args->pose_a, "Pose of a: \"tx ty tz [qw qx qy qz]\" (default identity)");
    sub->add_option("--pose-b", args->pose_b, "Pose of b (default identity)");
    args->builder.add_to(*sub);
    args->builder.add_refit_to(*sub);
    sub->add_flag("--first", args->first, "Stop at the first overlapping pair");
    sub->add_flag("--json", args->json, "Print {intersecting, pairs, bv_tests, primitive_tests} (and names)");
    sub->add_flag("--names", args->names, "Also print each pair's primitive names (JSON strings; \"\" for none)");
    sub->footer("Pairs are (primitive of a, primitive of b) in each file's order; survey XML lists primitives in\n"
                "tree order, so a model and a hierarchy built from it number them differently: --names says which.\n"
                "Example: hbvh collide data/models/chair.xml data/models/chair.xml --pose-b \"0.3 0 0\" --json");
    sub->callback([&command, args] { command = [args] { return run_collide(*args); }; });
}

}  // namespace hbvh::cli
