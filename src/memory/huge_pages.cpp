// SPDX-License-Identifier: MIT
#include "huge_pages.hpp"

#include <algorithm>
#include <cstdint>

#include <tbb/parallel_for.h>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace hbvh::detail {
namespace {

/// The whole 2 MiB pages inside [data, data + bytes), as [begin, end) addresses (begin == end: none). madvise
/// wants a page-aligned start, and a huge page that straddled the buffer's ends would share memory with other
/// allocations.
struct PageRange {
    std::uintptr_t begin = 0, end = 0;
};
constexpr std::uintptr_t huge_page = std::uintptr_t{2} << 20;
[[maybe_unused]] PageRange whole_huge_pages(void* data, std::size_t bytes) noexcept {
    if (data == nullptr || bytes < huge_page_advice_min_bytes) return {};
    const auto begin = (reinterpret_cast<std::uintptr_t>(data) + huge_page - 1) & ~(huge_page - 1);
    const auto end = (reinterpret_cast<std::uintptr_t>(data) + bytes) & ~(huge_page - 1);
    return end > begin ? PageRange{begin, end} : PageRange{};
}

}  // namespace

void advise_huge_pages(void* data, std::size_t bytes) noexcept {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    const PageRange pages = whole_huge_pages(data, bytes);
    if (pages.end > pages.begin) (void)madvise(reinterpret_cast<void*>(pages.begin), pages.end - pages.begin, MADV_HUGEPAGE);
#else
    (void)data;
    (void)bytes;
#endif
}

void populate_in_parallel(void* data, std::size_t bytes) noexcept {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
    const PageRange pages = whole_huge_pages(data, bytes);
    if (pages.end <= pages.begin) return;
    // Chunks of 8 huge pages: enough tasks for any core count, few enough madvise calls.
    constexpr std::uintptr_t chunk = 8 * huge_page;
    const std::size_t chunks = (pages.end - pages.begin + chunk - 1) / chunk;
    try {
        tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t i) {
            const std::uintptr_t from = pages.begin + i * chunk;
            const std::uintptr_t to = std::min<std::uintptr_t>(pages.end, from + chunk);
            (void)madvise(reinterpret_cast<void*>(from), to - from, MADV_POPULATE_WRITE);
        });
    } catch (...) {
        // Only a head start: pages not faulted in here are faulted in when first written.
    }
#else
    (void)data;
    (void)bytes;
#endif
}

}  // namespace hbvh::detail
