// SPDX-License-Identifier: MIT
#include "huge_pages.hpp"

#include <cstdint>

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

}  // namespace hbvh::detail
