// SPDX-License-Identifier: MIT
// Large buffers on 2 MiB pages. A build of 10^6 primitives first-touches about a gigabyte; in 4 KiB pages that
// is hundreds of thousands of page faults, and on the virtual machine of docs/scale.md §9 ("Page faults") they
// took 3.4 of `binned`'s 7.8 s; the binary loader saw the same (docs/formats.md). Linux backs memory with transparent huge
// pages where a program asks for them (madvise) even when they are not on for everything, so the library asks,
// for its own large buffers.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace hbvh::detail {

/// Buffers from this size on are advised: their 2 MiB-aligned interior then holds at least one huge page.
inline constexpr std::size_t huge_page_advice_min_bytes = std::size_t{4} << 20;

/// Asks the kernel to back the whole 2 MiB pages inside [data, data + bytes) with huge pages: Linux's
/// madvise(MADV_HUGEPAGE), nothing elsewhere or below huge_page_advice_min_bytes. Advice only: it changes no
/// value, and a refusal (a kernel without transparent huge pages) is ignored. Call it before the memory is
/// first written, since a page already touched stays small.
void advise_huge_pages(void* data, std::size_t bytes) noexcept;

/// Faults in the whole 2 MiB pages inside [data, data + bytes) on every core at once (Linux's
/// madvise(MADV_POPULATE_WRITE), from 5.14; nothing elsewhere, on older kernels or below
/// huge_page_advice_min_bytes). The kernel clears each fresh page when it is first written; a builder that fills a
/// large array from one thread would otherwise clear all of it on that thread. Changes no value.
void populate_in_parallel(void* data, std::size_t bytes) noexcept;

/// std::allocator, except that every large allocation is advised (advise_huge_pages) and faulted in on every core
/// (populate_in_parallel): a large array is allocated to be filled. For the builders' own large arrays; the
/// public types keep std::allocator and are advised after reserve().
template <class T>
struct HugePageAllocator {
    using value_type = T;
    HugePageAllocator() = default;
    template <class U>
    HugePageAllocator(const HugePageAllocator<U>& /*other*/) noexcept {}  // NOLINT: allocators convert implicitly

    [[nodiscard]] T* allocate(std::size_t count) {
        T* data = std::allocator<T>().allocate(count);
        advise_huge_pages(data, count * sizeof(T));
        populate_in_parallel(data, count * sizeof(T));
        return data;
    }
    void deallocate(T* data, std::size_t count) noexcept { std::allocator<T>().deallocate(data, count); }

    template <class U>
    bool operator==(const HugePageAllocator<U>& /*other*/) const noexcept {
        return true;
    }
};

/// A vector for a builder's arrays over every primitive or node.
template <class T>
using LargeVector = std::vector<T, HugePageAllocator<T>>;

/// reserve(count), then the advice, so that the elements written after it land on huge pages, and those pages
/// faulted in on every core. For a vector about to be filled to `count`.
template <class T, class Allocator>
void reserve_on_huge_pages(std::vector<T, Allocator>& vector, std::size_t count) {
    vector.reserve(count);
    advise_huge_pages(vector.data(), vector.capacity() * sizeof(T));
    populate_in_parallel(vector.data(), vector.capacity() * sizeof(T));
}

/// An empty string resized to `size` (zeros), its buffer advised before the zeros are written: for a file's
/// bytes read into it, or a format written into it.
inline void resize_on_huge_pages(std::string& text, std::size_t size) {
    text.reserve(size);
    advise_huge_pages(text.data(), text.capacity());
    text.resize(size);
}

}  // namespace hbvh::detail
