// SPDX-License-Identifier: MIT
#include "huge_pages.hpp"

#include <algorithm>
#include <cstdint>

#include <tbb/parallel_for.h>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace hbvh::detail {

void advise_huge_pages(void* data, std::size_t bytes) noexcept {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (data == nullptr || bytes < huge_page_advice_min_bytes) return;
    constexpr std::uintptr_t huge_page = std::uintptr_t{2} << 20;
    // The whole huge pages inside the buffer: madvise wants a page-aligned start, and a huge page that
    // straddles the buffer's ends would share memory with other allocations.
    const auto begin = (reinterpret_cast<std::uintptr_t>(data) + huge_page - 1) & ~(huge_page - 1);
    const auto end = (reinterpret_cast<std::uintptr_t>(data) + bytes) & ~(huge_page - 1);
    if (end > begin) (void)madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
    (void)data;
    (void)bytes;
#endif
}

void populate_in_parallel(void* data, std::size_t bytes) noexcept {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
    if (data == nullptr || bytes < huge_page_advice_min_bytes) return;
    constexpr std::uintptr_t huge_page = std::uintptr_t{2} << 20;
    const auto begin = (reinterpret_cast<std::uintptr_t>(data) + huge_page - 1) & ~(huge_page - 1);
    const auto end = (reinterpret_cast<std::uintptr_t>(data) + bytes) & ~(huge_page - 1);
    if (end <= begin) return;
    // Chunks of 8 huge pages: enough tasks for any core count, few enough madvise calls.
    constexpr std::uintptr_t chunk = 8 * huge_page;
    const std::size_t chunks = (end - begin + chunk - 1) / chunk;
    tbb::parallel_for(std::size_t{0}, chunks, [&](std::size_t i) {
        const std::uintptr_t from = begin + i * chunk;
        const std::uintptr_t to = std::min<std::uintptr_t>(end, from + chunk);
        (void)madvise(reinterpret_cast<void*>(from), to - from, MADV_POPULATE_WRITE);
    });
#else
    (void)data;
    (void)bytes;
#endif
}

}  // namespace hbvh::detail
