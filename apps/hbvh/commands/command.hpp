// SPDX-License-Identifier: MIT
// What every subcommand shares: how it registers, how it reads its input and writes its output,
// and how errors become messages and exit codes (0 ok, 1 bad input, 2 bad usage).
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "hbvh/builders/build.hpp"
#include "hbvh/io/model_file.hpp"
#include "hbvh/result.hpp"
#include "hbvh/tree/bvh.hpp"
#include "hbvh/tree/validate.hpp"

namespace hbvh::cli {

inline constexpr int exit_ok = 0;
inline constexpr int exit_bad_input = 1;
inline constexpr int exit_bad_usage = 2;

/// The action a subcommand's parse selected; run after parsing succeeds.
using Command = std::function<int()>;

/// Each subcommand adds itself to `app` and, when chosen, stores its action in `command`.
void add_algorithms_command(CLI::App& app, Command& command);
void add_build_command(CLI::App& app, Command& command);
void add_stats_command(CLI::App& app, Command& command);
void add_generate_command(CLI::App& app, Command& command);
void add_compare_command(CLI::App& app, Command& command);
void add_convert_command(CLI::App& app, Command& command);
void add_collide_command(CLI::App& app, Command& command);
void add_simulate_command(CLI::App& app, Command& command);
void add_export_command(CLI::App& app, Command& command);
void add_view_command(CLI::App& app, Command& command);
void add_calibrate_command(CLI::App& app, Command& command);

/// A loaded input: always the primitives; the hierarchy too when the file nests volumes.
struct Model : ModelFile {
    std::string source;  ///< The input's name in messages ("<stdin>" for "-").
};

/// Reads INPUT ("-" = stdin) in the format its extension says, or `format` when given.
[[nodiscard]] Result<Model> load_model(const std::string& path, const std::string& format = {});
/// Empty, or why writing `output` would destroy the input: `output` is the file `input` names (by any path or link)
/// and that file is an imported model (`input_imported`: MJCF, URDF or a mesh, of which survey XML and .hbvh keep only
/// the primitives) or, with `any_input`, anything (export's glTF, DOT or SVG in place of the file it was made from).
/// The caller prints it as a usage error (exit 2); an atomic write would otherwise replace the model silently.
[[nodiscard]] std::string output_replaces_input(const std::string& input, const std::string& output,
                                                bool input_imported, bool any_input = false);
/// Writes `content` to `path` atomically, or to stdout for "-".
[[nodiscard]] Status write_output(const std::string& path, const std::string& content);
/// Prints "hbvh: <where>: <message>" to stderr and returns exit_bad_input.
int report_error(const Error& error);
/// Prints warnings to stderr, one a line.
void report_warnings(const std::vector<std::string>& warnings);
/// Accepts a whole number from `least` to `most` and names both in its refusal ("'abc' is not a whole number from 1
/// to 1000"), where CLI::Range says "not in range" of a word that is no number at all.
[[nodiscard]] CLI::Validator whole_number(std::uint64_t least, std::uint64_t most);
/// Refuses what is not a decimal integer from 0 to 2^64 - 1 (CLI11 alone wraps "-1" and clamps larger values, so
/// different seeds on the command line gave the same scene).
[[nodiscard]] CLI::Validator seed_validator();
/// Refuses an output name whose extension is another format's (.gltf, .obj, .dot, .html, .urdf, ...) for the
/// commands that write survey XML or, for .hbvh, the binary format: XML written into x.gltf was read as glTF later.
[[nodiscard]] CLI::Validator hierarchy_output_name();
/// "1 leaf", "2 leaves": a count with its noun in the right number.
[[nodiscard]] inline std::string counted(std::uint64_t count, std::string_view singular, std::string_view plural) {
    return std::to_string(count) + " " + std::string(count == 1 ? singular : plural);
}

/// Refuses an empty output name (a usage error, exit 2).
[[nodiscard]] CLI::Validator output_name();
/// Refuses an input --format that no reader has (a usage error, exit 2, before any file is read; it was exit 1,
/// worded as a problem of the input file).
[[nodiscard]] CLI::Validator input_format();

/// A builder and what steers it, as the flags chose: the deadline starts when run() does.
struct BuildRequest {
    Algorithm algorithm = Algorithm::automatic;
    BuildContext context;             ///< Policy; progress and report are set by the caller.
    double time_limit_seconds = 0.0;  ///< 0: none.
    bool refine = false;              ///< Treelet refinement after the builder (build_refined).
    TreeletOptions treelets;
    /// Builds over `primitives` with the deadline counted from now.
    [[nodiscard]] Result<Bvh> run(std::span<const Primitive> primitives) const;
};

/// `algorithm`'s tree, refined when `refine` (build_refined); `auto` refines with `treelets` either way, so that
/// --treelet-units reaches it without --refine, as its help says.
[[nodiscard]] Result<Bvh> build_requested(std::span<const Primitive> primitives, Algorithm algorithm,
                                          const BuildContext& context, bool refine, const TreeletOptions& treelets);

/// Options that select and steer a builder, shared by build, stats, compare, collide.
struct BuilderFlags {
    std::string algorithm = "auto";
    std::string quality;  ///< --quality fast|auto: a preset naming the builder instead of -a.
    std::string types = "aabb,obb,sphere,capsule";
    std::string type_weights;
    std::string objective = "eq2";  ///< --objective: eq2 (the survey's volume) or calibrated (Minkowski measure).
    double time_limit_seconds = 0.0;  ///< --time-limit: anytime builders return the best found by then.
    bool refine = false;              ///< --refine: treelet refinement after any builder.
    std::uint32_t treelet_units = TreeletOptions{}.max_units;  ///< --treelet-units.
    bool refit = false;  ///< --refit: a stored hierarchy's non-enclosing volumes are refitted instead of refused.
    /// Adds the flags; without -a and --quality where the command picks its builders itself (compare's list).
    void add_to(CLI::App& command, bool choose_builder = true);
    /// Adds --refit, for the commands that query or draw a stored hierarchy.
    void add_refit_to(CLI::App& command);
    /// The build these flags ask for, or a usage Error.
    [[nodiscard]] Result<BuildRequest> resolve() const;
    /// Whether any flag that chooses or steers a build differs from its default (a stored hierarchy ignores them).
    [[nodiscard]] bool steer_a_build() const;
};

/// The build `flags` ask for, resolved once (a --type-weight @FILE is read once: it may be a pipe); nothing, after
/// "hbvh COMMAND: problem" on stderr, when they cannot be (the caller then exits with exit_bad_usage). Called
/// before any input is read, whatever the inputs turn out to hold, so that a bad flag is a usage error in every
/// command (it was exit 1 in those that build only when given a primitive set).
[[nodiscard]] std::optional<BuildRequest> resolve_or_report(const BuilderFlags& flags, std::string_view command);

/// Warns on stderr when `model` stores a hierarchy, which is used as it is (or `measured`, by stats, which weighs
/// its cost by --type-weight), and `flags` would steer a build (they apply to primitive sets only).
void warn_if_build_flags_unused(const Model& model, const BuilderFlags& flags, bool measured);

/// The model's stored hierarchy once it passes validate() (with flags.refit, its non-enclosing volumes
/// refitted and a note printed; a warning when `flags` would steer a build), or one built from its primitives with
/// `request` (resolve_or_report's, so that the flags are resolved once). A stored hierarchy that fails is refused
/// with "file:line: volume (obb) does not enclose primitive N ('name') by D".
[[nodiscard]] Result<Bvh> hierarchy_of(const Model& model, const BuildRequest& request, const BuilderFlags& flags);
/// Ok when the model has no stored hierarchy or its volumes enclose their primitives (or flags.refit, after
/// a note); for build, which rebuilds from the primitives but must not pass over a broken file in silence.
[[nodiscard]] Status check_stored_hierarchy(const Model& model, const BuilderFlags& flags);

}  // namespace hbvh::cli
