// SPDX-License-Identifier: MIT
// read_text_file and write_file_atomic (hbvh/files.hpp, core): contents, errors that name the file, nothing left behind.
#include "hbvh/files.hpp"

#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

namespace hbvh {
namespace {

namespace fs = std::filesystem;

/// A fresh empty directory per test, removed afterwards.
class FileTest : public testing::Test {
protected:
    void SetUp() override {
        const auto* info = testing::UnitTest::GetInstance()->current_test_info();
        directory_ = fs::temp_directory_path() / ("hbvh_io_test_" + std::to_string(::getpid()) + "_" + info->name());
        fs::remove_all(directory_);
        fs::create_directories(directory_);
    }
    void TearDown() override { fs::remove_all(directory_); }

    /// Names in the directory, to check that no temporary file is left over.
    [[nodiscard]] std::vector<std::string> entries() const {
        std::vector<std::string> names;
        for (const auto& entry : fs::directory_iterator(directory_)) names.push_back(entry.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }

    fs::path directory_;
};

TEST_F(FileTest, WriteThenReadGivesTheSameBytes) {
    std::string content = "line 1\r\nline 2\n";
    content += '\0';
    content += "\xFF after a zero byte";
    const fs::path path = directory_ / "out.xml";
    ASSERT_TRUE(write_file_atomic(path, content));
    const Result<std::string> read = read_text_file(path);
    ASSERT_TRUE(read) << read.error().to_string();
    EXPECT_EQ(*read, content);
    EXPECT_EQ(entries(), std::vector<std::string>{"out.xml"});
}

TEST_F(FileTest, ReplacesAnExistingFileAndKeepsItsPermissions) {
    const fs::path path = directory_ / "out.xml";
    std::ofstream(path) << "old content that is longer than the new";
    ::chmod(path.c_str(), 0640);
    ASSERT_TRUE(write_file_atomic(path, "new"));
    EXPECT_EQ(*read_text_file(path), "new");
    struct stat info {};
    ASSERT_EQ(::stat(path.c_str(), &info), 0);
    EXPECT_EQ(info.st_mode & 0777, 0640u);
    EXPECT_EQ(entries(), std::vector<std::string>{"out.xml"});
}

TEST_F(FileTest, EmptyContentMakesAnEmptyFile) {
    const fs::path path = directory_ / "empty";
    ASSERT_TRUE(write_file_atomic(path, ""));
    EXPECT_EQ(*read_text_file(path), "");
}

TEST_F(FileTest, FailureLeavesNothingBehind) {
    // The target is a directory: refused by name, and neither a temporary file nor anything in it is left.
    const fs::path target = directory_ / "taken";
    fs::create_directory(target);
    const Status status = write_file_atomic(target, "content");
    ASSERT_FALSE(status);
    EXPECT_EQ(status.error().file, target.string());
    EXPECT_EQ(status.error().message, "is a directory, not a file: give the output a file name");
    EXPECT_EQ(entries(), std::vector<std::string>{"taken"});
    EXPECT_TRUE(fs::is_empty(target));
}

// What a signal handler calls (the CLI's, on SIGINT, SIGTERM and SIGHUP): the temporary file of a write under way
// goes, the old file stays, and the write, when it resumes, fails instead of putting anything in place.
TEST_F(FileTest, PendingTemporaryFilesCanBeRemovedMidWrite) {
    const fs::path target = directory_ / "out.xml";
    ASSERT_TRUE(write_file_atomic(target, "old"));
    const std::string content(std::size_t{256} << 20, 'x');  // long enough to be seen in flight
    Status status = Ok{};
    std::atomic<bool> finished{false};
    std::thread writer([&] {
        status = write_file_atomic(target, content);
        finished = true;
    });
    bool seen = false;
    while (!seen && !finished) {
        for (const std::string& name : entries()) seen = seen || name.rfind(".out.xml.tmp-", 0) == 0;
        if (!seen) std::this_thread::sleep_for(std::chrono::microseconds(100));
    }
    if (seen) remove_pending_temporary_files();
    writer.join();
    ASSERT_TRUE(seen) << "the write ended before its temporary file was seen";
    ASSERT_FALSE(status);
    EXPECT_NE(status.error().message.find("cannot replace the file"), std::string::npos) << status.error().to_string();
    EXPECT_EQ(entries(), std::vector<std::string>{"out.xml"});
    const Result<std::string> kept = read_text_file(target);
    ASSERT_TRUE(kept) << kept.error().to_string();
    EXPECT_EQ(*kept, "old");
    // With nothing in flight it does nothing, and later writes are unaffected.
    remove_pending_temporary_files();
    ASSERT_TRUE(write_file_atomic(target, "new"));
    EXPECT_EQ(*read_text_file(target), "new");
}

TEST_F(FileTest, DotAndDotDotAreRefusedAsDirectories) {
    // rename() onto "." or ".." fails with EBUSY ("Device or resource busy"), which told a user nothing.
    for (const char* name : {".", ".."}) {
        const fs::path target = directory_ / name;
        const Status status = write_file_atomic(target, "content");
        ASSERT_FALSE(status) << name;
        EXPECT_EQ(status.error().message, "is a directory, not a file: give the output a file name");
    }
    EXPECT_TRUE(entries().empty());
}

TEST_F(FileTest, MissingDirectoryIsAnError) {
    const fs::path path = directory_ / "no" / "such" / "dir" / "out.xml";
    const Status status = write_file_atomic(path, "x");
    ASSERT_FALSE(status);
    EXPECT_EQ(status.error().file, path.string());
    EXPECT_NE(status.error().message.find("No such file or directory"), std::string::npos) << status.error().to_string();
    EXPECT_TRUE(entries().empty());
}

TEST_F(FileTest, ReadErrorsNameTheFile) {
    const fs::path missing = directory_ / "missing.xml";
    const Result<std::string> not_there = read_text_file(missing);
    ASSERT_FALSE(not_there);
    EXPECT_EQ(not_there.error().file, missing.string());
    EXPECT_EQ(not_there.error().line, 0);
    EXPECT_NE(not_there.error().message.find("No such file or directory"), std::string::npos);

    const Result<std::string> directory = read_text_file(directory_);
    ASSERT_FALSE(directory);
    EXPECT_NE(directory.error().message.find("directory"), std::string::npos);
}

TEST_F(FileTest, ReadsAFileLargerThanOneChunk) {
    const std::string content(300000, 'x');
    const fs::path path = directory_ / "big";
    ASSERT_TRUE(write_file_atomic(path, content));
    EXPECT_EQ(read_text_file(path)->size(), content.size());
}

TEST_F(FileTest, AStreamIsWrittenIntoNotReplaced) {
    // A fifo, and a symbolic link to it (as /dev/stdout links to the process's output): the bytes arrive in the
    // pipe, and both stay what they were instead of becoming regular files. The test holds the fifo open for
    // reading and writing without blocking, so the content (less than a pipe's buffer) needs no reader thread,
    // and a fifo replaced by a file shows as an empty read instead of a hang.
    const fs::path fifo = directory_ / "stream";
    const fs::path link = directory_ / "link";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    fs::create_symlink(fifo, link);
    const int pipe_end = ::open(fifo.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
    ASSERT_GE(pipe_end, 0);
    for (const fs::path& target : {fifo, link}) {
        const std::string content = "through " + target.filename().string() + std::string(3000, '.');
        const Status status = write_file_atomic(target, content);
        ASSERT_TRUE(status) << status.error().to_string();
        std::string received(8192, '\0');
        const ssize_t count = ::read(pipe_end, received.data(), received.size());
        received.resize(count > 0 ? static_cast<std::size_t>(count) : 0);
        EXPECT_EQ(received, content) << target;
    }
    ::close(pipe_end);
    EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link)));
    EXPECT_EQ(entries(), (std::vector<std::string>{"link", "stream"}));
}

TEST_F(FileTest, ALinkToAFileIsFollowedAndKept) {
    const fs::path file = directory_ / "file";
    const fs::path link = directory_ / "link";
    std::ofstream(file) << "old";
    fs::create_symlink(file, link);
    ASSERT_TRUE(write_file_atomic(link, "new"));
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link)));
    EXPECT_EQ(*read_text_file(file), "new");
    EXPECT_EQ(entries(), (std::vector<std::string>{"file", "link"}));

    // A link to a directory is refused and stays; a dangling one keeps its place and the file it names is made,
    // through a chain of relative links too (as a shell's `>` does).
    fs::create_directory(directory_ / "folder");
    fs::create_symlink(directory_ / "folder", directory_ / "to_folder");
    const Status refused = write_file_atomic(directory_ / "to_folder", "x");
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().message.find("directory"), std::string::npos) << refused.error().to_string();
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(directory_ / "to_folder")));
    EXPECT_TRUE(fs::is_empty(directory_ / "folder"));
    fs::create_symlink(directory_ / "nothing", directory_ / "dangling");
    ASSERT_TRUE(write_file_atomic(directory_ / "dangling", "made"));
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(directory_ / "dangling")));
    EXPECT_EQ(*read_text_file(directory_ / "nothing"), "made");
    fs::create_directory(directory_ / "sub");
    fs::create_symlink("sub/hop", directory_ / "first");
    fs::create_symlink("../target", directory_ / "sub" / "hop");
    ASSERT_TRUE(write_file_atomic(directory_ / "first", "chained"));
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(directory_ / "first")));
    EXPECT_EQ(*read_text_file(directory_ / "target"), "chained");
    // A loop of links is an error, not a hang.
    fs::create_symlink("loop_b", directory_ / "loop_a");
    fs::create_symlink("loop_a", directory_ / "loop_b");
    EXPECT_FALSE(write_file_atomic(directory_ / "loop_a", "x"));
}

TEST_F(FileTest, TheProcesssOwnStandardOutputIsWrittenThroughItsDescriptor) {
    // Standard output redirected to a file opened for appending (`>> log`), reached by a link as /dev/stdout
    // reaches it: the content is appended through descriptor 1, and the file is neither replaced nor
    // overwritten from its start.
    const fs::path log = directory_ / "log";
    std::ofstream(log) << "earlier\n";
    const fs::path link = directory_ / "stdout";
    fs::create_symlink(log, link);
    std::fflush(stdout);
    const int saved = ::dup(STDOUT_FILENO);
    ASSERT_GE(saved, 0);
    const int appended = ::open(log.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
    ASSERT_GE(appended, 0);
    ::dup2(appended, STDOUT_FILENO);
    ::close(appended);
    struct stat before {};
    ::stat(log.c_str(), &before);
    const Status status = write_file_atomic(link, "later\n");
    ::dup2(saved, STDOUT_FILENO);  // restored before any check can print
    ::close(saved);
    ASSERT_TRUE(status) << status.error().to_string();
    EXPECT_EQ(*read_text_file(log), "earlier\nlater\n");
    struct stat after {};
    ::stat(log.c_str(), &after);
    EXPECT_EQ(after.st_ino, before.st_ino);  // the same file, not a replacement
    EXPECT_TRUE(fs::is_symlink(fs::symlink_status(link)));
}

TEST_F(FileTest, ANameNearTheLengthLimitStillGetsATemporaryFile) {
    const fs::path path = directory_ / (std::string(240, 'a') + ".xml");  // 244 bytes: legal, 255 is the limit
    ASSERT_TRUE(write_file_atomic(path, "content"));
    EXPECT_EQ(*read_text_file(path), "content");
    EXPECT_EQ(entries().size(), 1u);
}

}  // namespace
}  // namespace hbvh
