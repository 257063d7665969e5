// SPDX-License-Identifier: MIT
// `hbvh export`: pictures of a hierarchy's levels (glTF 2.0) or of its tree (Graphviz DOT, or SVG via dot).
#include <fmt/core.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>

#include "commands/command.hpp"
#include "hbvh/io/export_dot.hpp"
#include "hbvh/io/export_gltf.hpp"
#include "hbvh/io/file.hpp"

extern char** environ;

namespace hbvh::cli {
namespace {
struct ExportArguments {
    std::string input;
    std::string input_format;
    std::string output;
    std::string format;
    BuilderFlags builder;
    bool overlay = false;
    bool no_carry = false;
};

/// The export format: --format when given, else the output's extension (in any case). A --format that contradicts
/// an extension naming another export format is refused: DOT written into x.gltf was taken for glTF later. The
/// flags of one format are refused with another (--overlay is glTF's, --no-carry DOT's and SVG's).
Result<std::string> export_format(const ExportArguments& args) {
    std::string extension = lower_case_extension(args.output);
    if (!extension.empty()) extension.erase(0, 1);
    const auto known = [](const std::string& name) { return name == "gltf" || name == "dot" || name == "svg"; };
    if (!args.format.empty() && known(extension) && args.format != extension)
        return Error{"--format " + args.format + " contradicts the output's extension ." + extension +
                     ": name the output ." + args.format + ", or leave --format out"};
    const std::string format = args.format.empty() ? extension : args.format;
    if (!known(format)) {
        if (format.empty()) return Error{"cannot tell the format of '" + args.output + "': use .gltf, .dot or .svg, or --format"};
        return Error{"unknown export format '" + format + "' (gltf, dot or svg)"};
    }
    if (args.overlay && format != "gltf") return Error{"--overlay is for glTF output, not " + format};
    if (args.no_carry && format == "gltf") return Error{"--no-carry is for DOT and SVG output, not glTF"};
    return format;
}

/// The full path of `program` on PATH, or empty when it is not there.
std::filesystem::path find_on_path(const std::string& program) {
    const char* path = std::getenv("PATH");
    std::string_view rest = path ? path : "";
    while (!rest.empty()) {
        const std::size_t colon = rest.find(':');
        const std::string_view dir = rest.substr(0, colon);
        rest = colon == std::string_view::npos ? std::string_view{} : rest.substr(colon + 1);
        const std::filesystem::path candidate = std::filesystem::path(dir.empty() ? "." : std::string(dir)) / program;
        if (::access(candidate.c_str(), X_OK) == 0 && !std::filesystem::is_directory(candidate)) return candidate;
    }
    return {};
}

/// A file descriptor closed when it goes out of scope.
class Descriptor {
public:
    explicit Descriptor(int fd = -1) : fd_(fd) {}
    Descriptor(const Descriptor&) = delete;
    Descriptor& operator=(const Descriptor&) = delete;
    ~Descriptor() { close(); }
    [[nodiscard]] int get() const { return fd_; }
    void close() {
        if (fd_ >= 0) ::close(fd_);
        fd_ = -1;
    }

private:
    int fd_;
};

/// Renders DOT text to SVG with Graphviz's `dot`, through its standard input and output. No shell is involved, so
/// no quoting of user paths can go wrong, and no scratch file either: until 2026-12-08 dot read and wrote files in a
/// private temporary directory, which a signal ending hbvh mid-render left behind in $TMPDIR.
Result<std::string> render_svg(const std::string& dot_text) {
    const std::filesystem::path dot = find_on_path("dot");
    if (dot.empty()) return Error{"Graphviz 'dot' was not found on PATH; install graphviz, or write .dot instead"};
    // One connected socket pair rather than two pipes: the child's end is its stdin and stdout, and the parent's
    // send(MSG_NOSIGNAL) turns a dot that exits before reading everything into an error instead of a SIGPIPE.
    int ends[2];
    if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, ends) != 0)
        return Error{std::string("cannot connect to Graphviz 'dot': ") + std::strerror(errno)};
    Descriptor ours(ends[0]);
    Descriptor theirs(ends[1]);
    posix_spawn_file_actions_t actions;
    ::posix_spawn_file_actions_init(&actions);
    // dup2 clears close-on-exec on the copies, so the child keeps exactly these two.
    ::posix_spawn_file_actions_adddup2(&actions, theirs.get(), STDIN_FILENO);
    ::posix_spawn_file_actions_adddup2(&actions, theirs.get(), STDOUT_FILENO);
    std::string program = dot.string();
    std::string type_flag = "-Tsvg";
    char* argv[] = {program.data(), type_flag.data(), nullptr};
    pid_t child = 0;
    const int spawned = ::posix_spawn(&child, program.c_str(), &actions, nullptr, argv, environ);
    ::posix_spawn_file_actions_destroy(&actions);
    if (spawned != 0) return Error{"cannot run " + program + ": " + std::strerror(spawned)};
    theirs.close();  // so that the parent sees the end of dot's output when dot exits

    // dot may write while it still reads, so the text goes in on a thread of its own while this one reads.
    bool sent = true;
    std::thread sender([&] {
        std::size_t offset = 0;
        while (offset < dot_text.size()) {
            const ssize_t n = ::send(ours.get(), dot_text.data() + offset, dot_text.size() - offset, MSG_NOSIGNAL);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) {
                sent = false;
                break;
            }
            offset += static_cast<std::size_t>(n);
        }
        ::shutdown(ours.get(), SHUT_WR);  // end of input for dot
    });
    std::string svg;
    char buffer[1 << 16];
    for (;;) {
        const ssize_t n = ::read(ours.get(), buffer, sizeof buffer);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        svg.append(buffer, static_cast<std::size_t>(n));
    }
    sender.join();
    int status = 0;
    pid_t waited = 0;
    do waited = ::waitpid(child, &status, 0);
    while (waited < 0 && errno == EINTR);
    if (waited < 0 || !sent || !WIFEXITED(status) || WEXITSTATUS(status) != 0 || svg.empty())
        return Error{"Graphviz 'dot' failed to render the tree (see its message above)"};
    return svg;
}

int run_export(const ExportArguments& args) {
    const std::optional<BuildRequest> request = resolve_or_report(args.builder, "export");
    if (!request) return exit_bad_usage;
    Result<std::string> format = export_format(args);
    if (!format) {
        report_error(format.error());
        return exit_bad_usage;
    }
    // glTF, DOT and SVG are no input of hbvh's, so an export over its own input loses it whatever that was.
    if (const std::string problem = output_replaces_input(args.input, args.output, false, true); !problem.empty()) {
        fmt::print(stderr, "hbvh export: {}\n", problem);
        return exit_bad_usage;
    }
    Result<Model> model = load_model(args.input, args.input_format);
    if (!model) return report_error(model.error());
    report_warnings(model->warnings);
    Result<Bvh> bvh = hierarchy_of(model.value(), *request, args.builder);
    if (!bvh) return report_error(bvh.error());

    std::string content;
    if (*format == "gltf") {
        GltfOptions options;
        options.side_by_side = !args.overlay;
        Result<std::string> gltf = export_gltf(bvh.value(), options);
        if (!gltf) return report_error(Error{gltf.error().message, args.input});
        content = std::move(gltf.value());
    } else {
        content = export_dot(bvh.value(), {.carry_leaves = !args.no_carry});
        if (*format == "svg") {
            Result<std::string> svg = render_svg(content);
            if (!svg) return report_error(svg.error());
            content = std::move(svg.value());
        }
    }
    if (Status written = write_output(args.output, content); !written) return report_error(written.error());
    return exit_ok;
}
}  // namespace

void add_export_command(CLI::App& app, Command& command) {
    auto args = std::make_shared<ExportArguments>();
    CLI::App* sub = app.add_subcommand(
        "export", "Pictures of a hierarchy: its levels as glTF 2.0 meshes, or its tree as Graphviz DOT / SVG");
    sub->add_option("file", args->input, "Hierarchy file, or a primitive set (built first with -a)")->required();
    sub->add_option("-o,--output", args->output, "Output .gltf, .dot or .svg, or - for stdout (with --format)")
        ->required()
        ->check(output_name());
    sub->add_option("--format", args->format, "gltf, dot or svg, when the output's extension does not tell")
        ->check(CLI::IsMember({"gltf", "dot", "svg"}));
    sub->add_option("--input-format", args->input_format, "Input format when the extension does not tell")
        ->check(input_format());
    args->builder.add_to(*sub);
    args->builder.add_refit_to(*sub);
    sub->add_flag("--overlay", args->overlay, "glTF: put all levels at the same place instead of side by side");
    sub->add_flag("--no-carry", args->no_carry,
                  "DOT/SVG: draw each leaf under its parent, without grey copies down to the bottom row");
    sub->footer("Examples: hbvh export data/models/chair.xml -o chair.gltf\n"
                "          hbvh export chair.hbvh.xml -o chair.svg   (needs Graphviz's dot on PATH)\n"
                "See docs/export.md.");
    sub->callback([&command, args] { command = [args] { return run_export(*args); }; });
}

}  // namespace hbvh::cli
