// SPDX-License-Identifier: MIT
// src/memory/huge_pages.hpp: that a large LargeVector's interior really is advised, read back from the kernel's
// own account of the process's memory (/proc/self/smaps: "hg" among an area's VmFlags), and that a small one
// and a buffer's partial huge pages at its ends are left alone. Skipped where there is no such account or
// transparent huge pages are off.
#include <gtest/gtest.h>
#include <sys/mman.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

#include "memory/huge_pages.hpp"

namespace hbvh {
namespace {

/// The VmFlags of the mapping that holds `address`, or "" when /proc/self/smaps does not list it.
std::string flags_at(const void* address) {
    std::ifstream smaps("/proc/self/smaps");
    const auto target = reinterpret_cast<std::uintptr_t>(address);
    std::string line;
    bool inside = false;
    while (std::getline(smaps, line)) {
        std::uintptr_t begin = 0, end = 0;
        char dash = 0;
        std::istringstream range(line);
        if (range >> std::hex >> begin >> dash >> end && dash == '-') {
            inside = begin <= target && target < end;
            continue;
        }
        if (inside && line.rfind("VmFlags:", 0) == 0) return line;
    }
    return "";
}

bool huge_pages_available() {
    std::ifstream mode("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string text;
    std::getline(mode, text);
    return !text.empty() && text.find("[never]") == std::string::npos && !flags_at(&text).empty();
}

bool advised(const void* address) { return flags_at(address).find(" hg") != std::string::npos; }

constexpr std::uintptr_t huge_page = std::uintptr_t{2} << 20;

/// On a mapping of its own (so no allocator's choices enter): the whole huge pages inside the buffer are
/// advised, the partial ones at its two ends are not (they may hold other allocations).
TEST(HugePages, TheInteriorOfABufferIsAdvisedAndItsEdgesAreNot) {
    if (!huge_pages_available()) GTEST_SKIP() << "no /proc/self/smaps or transparent huge pages are off";
    constexpr std::size_t mapped = 16 * huge_page;
    void* mapping = ::mmap(nullptr, mapped, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    ASSERT_NE(mapping, MAP_FAILED);
    // A buffer that starts 3 KiB past the first huge-page boundary inside the mapping and ends 5 KiB short of
    // another, so that both of its ends are partial huge pages.
    const std::uintptr_t boundary = (reinterpret_cast<std::uintptr_t>(mapping) + huge_page - 1) & ~(huge_page - 1);
    auto* data = reinterpret_cast<char*>(boundary + 3 * 1024);
    const std::size_t bytes = 8 * huge_page - 3 * 1024 - 5 * 1024;
    detail::advise_huge_pages(data, bytes);
    EXPECT_FALSE(advised(data)) << flags_at(data);
    EXPECT_TRUE(advised(reinterpret_cast<const void*>(boundary + huge_page))) << flags_at(data + huge_page);
    EXPECT_TRUE(advised(reinterpret_cast<const void*>(boundary + 6 * huge_page)));
    EXPECT_FALSE(advised(data + bytes - 1));
    detail::advise_huge_pages(mapping, huge_page);  // below huge_page_advice_min_bytes: nothing
    EXPECT_FALSE(advised(mapping));
    ::munmap(mapping, mapped);
}

/// LargeVector asks for its large buffers (AddressSanitizer's allocator is not glibc's: skipped there).
TEST(HugePages, ALargeVectorIsAdvisedAndASmallOneIsNot) {
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP() << "AddressSanitizer's allocator";
#endif
    if (!huge_pages_available()) GTEST_SKIP() << "no /proc/self/smaps or transparent huge pages are off";
    constexpr std::size_t count = (std::size_t{24} << 20) / sizeof(double);  // 24 MiB
    const detail::LargeVector<double> large(count, 1.5);
    const std::uintptr_t interior = (reinterpret_cast<std::uintptr_t>(large.data()) + huge_page - 1) & ~(huge_page - 1);
    EXPECT_TRUE(advised(reinterpret_cast<const void*>(interior + huge_page))) << flags_at(large.data());
    EXPECT_EQ(large[count / 2], 1.5);  // advice changes no value
    const detail::LargeVector<double> small(1000, 2.5);  // 8 KB
    EXPECT_FALSE(advised(small.data()));
}

}  // namespace
}  // namespace hbvh
