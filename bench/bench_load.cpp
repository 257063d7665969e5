// SPDX-License-Identifier: MIT
// Loading a stored hierarchy at start-up: the .hbvh binary format against the survey XML, same tree, same disk.
// The files are written once to a temporary directory (outside the timings, removed at exit); each timed
// iteration reads one from disk and parses it completely (the binary reader also checks the CRC-64 and every
// check of check_structure, the XML reader does neither; the XML reader returns XmlModel, which holds the
// primitives twice, in the Bvh and beside it, since that is the only way XML gives a Bvh). One untimed load
// before each row. Counter speedup_vs_xml on the binary row: XML time / binary time.
//
//   hbvh_bench --benchmark_filter='load_.*/20k'   (a split tree over 20 000 primitives, a second)
//   hbvh_bench --benchmark_filter='load_.*/1M'    (a two-level tree over 10^6 primitives; the XML takes seconds)
// load_query_tree/1M: the .hbvh straight into the query layout, what a program waits for before its first query,
// against read_binary_file + QueryTree::create beside it. load_floor/1M: reading the file's bytes and writing the
// Bvh's once each, nothing else: what bounds any binary load's speed-up over the XML on this machine.
//
// Reading and writing a large primitive set (docs/formats.md, "Reading and writing large XML"): the survey's flat
// format, 10^6 primitives of `generate_scene` (about 230 MB, what `hbvh generate --count 1000000` writes). Rows, in
// the order they run: pugixml_inplace, the anchor, pugixml's bare in-place parse of the file's text (a fresh copy
// per iteration, outside the time; the DOM only, no conversion: what a harness built on pugixml pays at least);
// read_xml_set, read_xml_file from disk (page cache) to the primitives; write_xml_set, write_primitives_xml and
// write_file_atomic (with its fsync) to a file next to the input, with counters format_s and write_s for the parts.
//
//   hbvh_bench --benchmark_filter='xml_set|pugixml'   (about half a minute, most of it making the file)
#include <benchmark/benchmark.h>
// pugixml for the anchor row: linked through hbvh::io's static archive, which carries it as a link-only dependency.
#include <pugixml.hpp>

#include <sys/mman.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <iterator>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "hbvh/builders/build.hpp"
#include "hbvh/io/file.hpp"
#include "hbvh/io/xml.hpp"
#include "hbvh/query/tandem_traversal.hpp"
#include "hbvh/scene/generate.hpp"
#include "hbvh/tree/binary_format.hpp"
#include "memory/huge_pages.hpp"
#include "tree/binary_decoding.hpp"

namespace hbvh::bench {
void fail(benchmark::State& state, const std::string& message);

namespace {

/// One tree in both formats on disk.
struct StoredTree {
    std::filesystem::path xml;
    std::filesystem::path binary;
    std::size_t primitives = 0;
    std::size_t nodes = 0;
    std::size_t binary_bytes = 0;
    std::size_t xml_bytes = 0;
};

/// The temporary directory and the files in it, made once per size; removed when the program ends.
class StoredTrees {
public:
    ~StoredTrees() {
        std::error_code ignored;
        if (!dir_.empty()) std::filesystem::remove_all(dir_, ignored);
    }
    /// The files for `count` primitives, or an Error if building or writing failed.
    Result<StoredTree> get(std::uint32_t count) {
        if (const auto found = trees_.find(count); found != trees_.end()) return found->second;
        const std::filesystem::path& dir = directory();
        SceneOptions options;
        options.count = count;
        options.seed = 2024;
        const std::vector<Primitive> primitives = generate_scene(options);
        // split is the realistic tree but needs minutes at 10^6; two-level is built in well under a second.
        Result<Bvh> bvh = build(primitives, count <= 20'000 ? Algorithm::split : Algorithm::two_level);
        if (!bvh) return bvh.error();
        StoredTree tree;
        tree.xml = dir / (std::to_string(count) + ".xml");
        tree.binary = dir / (std::to_string(count) + ".hbvh");
        const std::string xml = write_xml(bvh.value());
        if (Status written = write_file_atomic(tree.xml, xml); !written) return written.error();
        if (Status written = write_binary_file(tree.binary, bvh.value()); !written) return written.error();
        tree.primitives = bvh->primitives.size();
        tree.nodes = bvh->nodes.size();
        tree.xml_bytes = xml.size();
        tree.binary_bytes = std::filesystem::file_size(tree.binary);
        trees_.emplace(count, tree);
        return tree;
    }

    /// The temporary directory, made on first use.
    const std::filesystem::path& directory() {
        if (dir_.empty()) {
            dir_ = std::filesystem::temp_directory_path() / ("hbvh_bench_load_" + std::to_string(::getpid()));
            std::filesystem::create_directories(dir_);
        }
        return dir_;
    }

private:
    std::filesystem::path dir_;
    std::map<std::uint32_t, StoredTree> trees_;
};

StoredTrees& stored_trees() {
    static StoredTrees trees;
    return trees;
}

/// Seconds per XML load, per size, for the binary row's ratio (the XML row runs first).
std::map<std::uint32_t, double>& xml_seconds() {
    static std::map<std::uint32_t, double> seconds;
    return seconds;
}

void load_xml(benchmark::State& state, std::uint32_t count) {
    Result<StoredTree> tree = stored_trees().get(count);
    if (!tree) return fail(state, tree.error().to_string());
    std::size_t loaded_nodes = 0;
    benchmark::DoNotOptimize(read_xml_file(tree->xml));  // untimed warm-up, as for the binary row
    const auto start = std::chrono::steady_clock::now();
    for (auto _ : state) {
        Result<XmlModel> model = read_xml_file(tree->xml);
        loaded_nodes = model && model->hierarchy ? model->hierarchy->nodes.size() : 0;
        benchmark::DoNotOptimize(loaded_nodes);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (loaded_nodes != tree->nodes) return fail(state, "the XML file did not load back as the tree written");
    xml_seconds()[count] = seconds / static_cast<double>(state.iterations());
    state.counters["primitives"] = static_cast<double>(tree->primitives);
    state.counters["MB"] = static_cast<double>(tree->xml_bytes) / 1e6;
}

void load_binary(benchmark::State& state, std::uint32_t count) {
    Result<StoredTree> tree = stored_trees().get(count);
    if (!tree) return fail(state, tree.error().to_string());
    std::size_t loaded_nodes = 0;
    // Untimed warm-up: the first load in a process may have to get its (huge) pages from the kernel afresh,
    // which on the virtual machine of docs/formats.md ("Load time") costs seconds at 10^6 primitives; the rows
    // measure the steady state, both formats alike.
    benchmark::DoNotOptimize(read_binary_file(tree->binary));
    const auto start = std::chrono::steady_clock::now();
    for (auto _ : state) {
        Result<Bvh> bvh = read_binary_file(tree->binary);
        loaded_nodes = bvh ? bvh->nodes.size() : 0;
        benchmark::DoNotOptimize(loaded_nodes);
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (loaded_nodes != tree->nodes) return fail(state, "the .hbvh file did not load back as the tree written");
    state.counters["primitives"] = static_cast<double>(tree->primitives);
    state.counters["MB"] = static_cast<double>(tree->binary_bytes) / 1e6;
    if (const auto xml = xml_seconds().find(count); xml != xml_seconds().end())
        state.counters["speedup_vs_xml"] = xml->second / (seconds / static_cast<double>(state.iterations()));
}

/// What a program that loads a tree at start-up to query it waits for: QueryTree::read_binary_file, the .hbvh
/// straight into the query layout (the row's time). Each iteration also loads it the long way, read_binary_file
/// then QueryTree::create (which checks the structure again), untimed by the row. Counters: via_bvh_ms, the long
/// way; convert_ms, its conversion; speedup_vs_xml, (XML load + conversion) / this row.
void load_query_tree(benchmark::State& state, std::uint32_t count) {
    Result<StoredTree> tree = stored_trees().get(count);
    if (!tree) return fail(state, tree.error().to_string());
    benchmark::DoNotOptimize(QueryTree::read_binary_file(tree->binary));  // untimed warm-up, as for the other rows
    using Clock = std::chrono::steady_clock;
    auto seconds_since = [](Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); };
    double direct_seconds = 0.0, via_bvh_seconds = 0.0, convert_seconds = 0.0;
    std::size_t direct_nodes = 0, via_bvh_nodes = 0;
    for (auto _ : state) {
        auto start = Clock::now();
        {
            Result<QueryTree> direct = QueryTree::read_binary_file(tree->binary);
            direct_nodes = direct ? direct->nodes().size() : 0;
            benchmark::DoNotOptimize(direct_nodes);
        }  // freed inside the time, as the long way's trees are
        const double direct = seconds_since(start);
        state.SetIterationTime(direct);
        direct_seconds += direct;
        start = Clock::now();
        {
            Result<Bvh> bvh = read_binary_file(tree->binary);
            const auto read = Clock::now();
            Result<QueryTree> converted = bvh ? QueryTree::create(*bvh) : bvh.error();
            convert_seconds += seconds_since(read);
            via_bvh_nodes = converted ? converted->nodes().size() : 0;
            benchmark::DoNotOptimize(via_bvh_nodes);
        }
        via_bvh_seconds += seconds_since(start);
    }
    if (direct_nodes != tree->nodes || via_bvh_nodes != tree->nodes) return fail(state, "the .hbvh file did not load as the tree written");
    const auto iterations = static_cast<double>(state.iterations());
    state.counters["via_bvh_ms"] = 1e3 * via_bvh_seconds / iterations;
    state.counters["convert_ms"] = 1e3 * convert_seconds / iterations;
    if (const auto xml = xml_seconds().find(count); xml != xml_seconds().end())
        state.counters["speedup_vs_xml"] = (xml->second + convert_seconds / iterations) / (direct_seconds / iterations);
}

/// The least any load of the .hbvh into a Bvh must do, for the binary row's speed-up to be read against: every
/// byte of the file read once (mapped from the page cache, summed) and every byte of the Bvh's two arrays
/// (nodes x sizeof(Node) + primitives x sizeof(Primitive)) written once into fresh memory advised into 2 MiB
/// pages, as the loader's are; both halves of each on the two threads at once. No decoding, no checks, no CRC.
/// Counter max_speedup_vs_xml: XML load / this row, the ratio no loader producing a Bvh can beat on this machine.
void load_floor(benchmark::State& state, std::uint32_t count) {
    Result<StoredTree> tree = stored_trees().get(count);
    if (!tree) return fail(state, tree.error().to_string());
    const std::size_t output_bytes = tree->nodes * sizeof(Node) + tree->primitives * sizeof(Primitive);
    std::uint64_t checksum = 0;
    // The file's bytes as the loader gets them (detail::with_file_bytes: mapped when large), the output as fresh
    // memory advised as the loader advises its arrays.
    auto once = [&]() -> Status {
        void* output = ::mmap(nullptr, output_bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (output == MAP_FAILED) return Error{"mmap of the output failed"};
        detail::advise_huge_pages(output, output_bytes);
        const Status read = detail::with_file_bytes(tree->binary, [&](std::span<const std::byte> file) {
            std::uint64_t sums[2] = {0, 0};
            auto half = [&](int k) {
                const auto* words = reinterpret_cast<const std::uint64_t*>(file.data());
                const std::size_t word_count = file.size() / sizeof(std::uint64_t);
                std::uint64_t sum = 0;
                for (std::size_t i = k * word_count / 2; i < (k + 1) * word_count / 2; ++i) sum += words[i];
                sums[k] = sum;
                std::memset(static_cast<char*>(output) + k * (output_bytes / 2), 1,
                            k == 0 ? output_bytes / 2 : output_bytes - output_bytes / 2);
            };
            std::thread other(half, 1);
            half(0);
            other.join();
            checksum += sums[0] + sums[1] + static_cast<unsigned char*>(output)[output_bytes - 1];
        });
        ::munmap(output, output_bytes);
        return read;
    };
    Status done = once();  // untimed warm-up, as for the other rows
    const auto start = std::chrono::steady_clock::now();
    for (auto _ : state) {
        if (done) done = once();
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!done) return fail(state, done.error().to_string());
    benchmark::DoNotOptimize(checksum);
    state.counters["MB_read"] = static_cast<double>(tree->binary_bytes) / 1e6;
    state.counters["MB_written"] = static_cast<double>(output_bytes) / 1e6;
    if (const auto xml = xml_seconds().find(count); xml != xml_seconds().end())
        state.counters["max_speedup_vs_xml"] = xml->second / (seconds / static_cast<double>(state.iterations()));
}

/// The 10^6-primitive set on disk, written once per process into the same temporary directory.
struct StoredSet {
    std::filesystem::path xml;
    std::vector<Primitive> primitives;
    std::size_t xml_bytes = 0;
};

Result<const StoredSet*> stored_set() {
    static std::optional<StoredSet> set;
    if (set) return &*set;
    SceneOptions options;
    options.count = 1'000'000;
    options.seed = 2024;
    StoredSet made;
    made.primitives = generate_scene(options);
    made.xml = stored_trees().directory() / "set_1M.xml";
    const std::string xml = write_primitives_xml(made.primitives);
    if (Status written = write_file_atomic(made.xml, xml); !written) return written.error();
    made.xml_bytes = xml.size();
    set = std::move(made);
    return &*set;
}

void pugixml_inplace(benchmark::State& state) {
    const Result<const StoredSet*> set = stored_set();
    if (!set) return fail(state, set.error().to_string());
    const Result<std::string> text = read_text_file((*set)->xml);
    if (!text) return fail(state, text.error().to_string());
    std::string buffer;
    std::size_t volumes = 0;
    for (auto _ : state) {
        buffer = *text;  // the parse writes into its buffer, so each iteration parses a fresh copy (untimed)
        pugi::xml_document document;
        const auto start = std::chrono::steady_clock::now();
        const pugi::xml_parse_result parsed = document.load_buffer_inplace(buffer.data(), buffer.size());
        state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        if (!parsed) return fail(state, parsed.description());
        volumes = static_cast<std::size_t>(std::distance(document.first_child().begin(), document.first_child().end()));
    }
    // Children of <hierarchy> are the volumes and nothing else (the writer puts no text between them).
    if (volumes != (*set)->primitives.size()) return fail(state, "pugixml did not find every volume");
    state.counters["MB"] = static_cast<double>(text->size()) / 1e6;
}

void read_xml_set(benchmark::State& state) {
    const Result<const StoredSet*> set = stored_set();
    if (!set) return fail(state, set.error().to_string());
    std::size_t primitives = 0;
    benchmark::DoNotOptimize(read_xml_file((*set)->xml));  // untimed warm-up, as for the other rows
    for (auto _ : state) {
        Result<XmlModel> model = read_xml_file((*set)->xml);
        primitives = model && !model->hierarchy ? model->primitives.size() : 0;
        benchmark::DoNotOptimize(primitives);
    }
    if (primitives != (*set)->primitives.size()) return fail(state, "the XML file did not read back as the set written");
    state.counters["MB"] = static_cast<double>((*set)->xml_bytes) / 1e6;
}

void write_xml_set(benchmark::State& state) {
    const Result<const StoredSet*> set = stored_set();
    if (!set) return fail(state, set.error().to_string());
    const std::filesystem::path output = (*set)->xml.parent_path() / "set_1M_written.xml";
    double format_seconds = 0.0;
    double write_seconds = 0.0;
    std::size_t bytes = 0;
    for (auto _ : state) {
        const auto start = std::chrono::steady_clock::now();
        const std::string xml = write_primitives_xml((*set)->primitives);
        const auto formatted = std::chrono::steady_clock::now();
        if (Status written = write_file_atomic(output, xml); !written) return fail(state, written.error().to_string());
        format_seconds += std::chrono::duration<double>(formatted - start).count();
        write_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - formatted).count();
        bytes = xml.size();
    }
    if (bytes != (*set)->xml_bytes) return fail(state, "the written text differs in size from the stored file");
    const auto iterations = static_cast<double>(state.iterations());
    state.counters["format_s"] = format_seconds / iterations;
    state.counters["write_s"] = write_seconds / iterations;
    state.counters["MB"] = static_cast<double>(bytes) / 1e6;
}

BENCHMARK_CAPTURE(load_xml, 20k, 20'000u)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK_CAPTURE(load_binary, 20k, 20'000u)->Unit(benchmark::kMillisecond)->Iterations(20);
BENCHMARK_CAPTURE(load_query_tree, 20k, 20'000u)->Unit(benchmark::kMillisecond)->Iterations(20)->UseManualTime();
BENCHMARK_CAPTURE(load_xml, 1M, 1'000'000u)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK_CAPTURE(load_binary, 1M, 1'000'000u)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK_CAPTURE(load_query_tree, 1M, 1'000'000u)->Unit(benchmark::kMillisecond)->Iterations(5)->UseManualTime();
BENCHMARK_CAPTURE(load_floor, 1M, 1'000'000u)->Unit(benchmark::kMillisecond)->Iterations(5);
BENCHMARK(pugixml_inplace)->Name("pugixml_inplace/1M")->Unit(benchmark::kMillisecond)->Iterations(3)->UseManualTime();
BENCHMARK(read_xml_set)->Name("read_xml_set/1M")->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(write_xml_set)->Name("write_xml_set/1M")->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace
}  // namespace hbvh::bench
