// SPDX-License-Identifier: MIT
// use_huge_pages_for_xml: a bump allocator over huge-page regions for pugixml's blocks.
#include "hbvh/io/xml_memory.hpp"

#include <pugixml.hpp>

#include <cstdint>
#include <cstdlib>
#include <functional>
#include <iterator>
#include <map>
#include <mutex>

#include "../memory/huge_pages.hpp"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace hbvh {
namespace {

/// Large enough that a 230 MB file's DOM takes a handful of regions, small enough that a small file's few
/// blocks reserve (not touch) little.
constexpr std::size_t region_bytes = std::size_t{64} << 20;
/// pugixml asks for 32 KiB pages and, for a long text or name, one block of that size; anything above a
/// quarter region goes to malloc, so that one huge block cannot strand most of a region.
constexpr std::size_t largest_region_block = region_bytes / 4;
/// malloc's guarantee, which pugixml's node and attribute structs rely on.
constexpr std::size_t block_alignment = alignof(std::max_align_t);

struct Region {
    std::size_t used = 0;
    std::size_t live = 0;
};

/// Regions by their start address, so that a block finds its region (or that it has none) by one search.
struct Regions {
    std::mutex mutex;
    std::map<std::uintptr_t, Region, std::less<>> by_start;
    std::uintptr_t current = 0;  // the region new blocks come from; 0 when there is none
};

Regions& regions() {
    // Never destroyed: a document destroyed at exit, after this file's statics, still frees its blocks here.
    static Regions* const instance = new Regions;
    return *instance;
}

void* map_region() {
#if defined(__linux__)
    void* start = mmap(nullptr, region_bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (start == MAP_FAILED) return nullptr;
    detail::advise_huge_pages(start, region_bytes);
    return start;
#else
    return nullptr;
#endif
}

void unmap_region(std::uintptr_t start) {
#if defined(__linux__)
    (void)munmap(reinterpret_cast<void*>(start), region_bytes);
#else
    (void)start;
#endif
}

void* allocate(std::size_t bytes) {
    const std::size_t rounded = (bytes + block_alignment - 1) / block_alignment * block_alignment;
    if (rounded > largest_region_block || rounded == 0) return std::malloc(bytes);
    Regions& all = regions();
    const std::lock_guard lock(all.mutex);
    Region* region = all.current != 0 ? &all.by_start.at(all.current) : nullptr;
    if (region == nullptr || region->used + rounded > region_bytes) {
        void* start = map_region();
        if (start == nullptr) return std::malloc(bytes);  // no mapping to be had: malloc's pages will do
        // The full region stays until its last block is freed (deallocate unmaps it then).
        all.current = reinterpret_cast<std::uintptr_t>(start);
        region = &all.by_start[all.current];
    }
    void* block = reinterpret_cast<void*>(all.current + region->used);
    region->used += rounded;
    ++region->live;
    return block;
}

void deallocate(void* block) {
    if (block == nullptr) return;
    const auto address = reinterpret_cast<std::uintptr_t>(block);
    Regions& all = regions();
    {
        const std::lock_guard lock(all.mutex);
        auto after = all.by_start.upper_bound(address);
        if (after != all.by_start.begin()) {
            const auto region = std::prev(after);
            if (address < region->first + region_bytes) {
                if (--region->second.live == 0) {
                    if (region->first == all.current) all.current = 0;
                    unmap_region(region->first);
                    all.by_start.erase(region);
                }
                return;
            }
        }
    }
    std::free(block);  // from malloc: before the switch, too large for a region, or when mapping failed
}

}  // namespace

void use_huge_pages_for_xml() { pugi::set_memory_management_functions(allocate, deallocate); }

namespace detail {
XmlMemoryUse xml_memory_use() {
    Regions& all = regions();
    const std::lock_guard lock(all.mutex);
    XmlMemoryUse use;
    use.regions = all.by_start.size();
    for (const auto& [start, region] : all.by_start) use.live_blocks += region.live;
    return use;
}
}  // namespace detail

}  // namespace hbvh
