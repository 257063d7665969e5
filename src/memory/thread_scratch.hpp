// SPDX-License-Identifier: MIT
// Per-thread scratch arrays that keep small memory between calls and give large memory back.
#pragma once

#include <cstddef>
#include <tuple>
#include <vector>

namespace hbvh::detail {

/// The fitters and estimators run tens of thousands of times per small build, each time over a few hundred
/// spheres; per-thread arrays that keep their capacity spare them the allocator (heaptrack counted 324 000 calls
/// in one `auto` build of 40 primitives, 104 000 after). A large set (the root of a 10^6-primitive scene) would
/// leave hundreds of megabytes held on every thread for the rest of the process, so an array grown past this
/// is given back after its call: that call allocated as before, and nothing large stays.
inline constexpr std::size_t thread_scratch_keep_bytes = std::size_t{1} << 20;

/// Frees `scratch`'s memory when it holds more than thread_scratch_keep_bytes.
template <class T>
void release_if_large(std::vector<T>& scratch) {
    if (scratch.capacity() * sizeof(T) > thread_scratch_keep_bytes) std::vector<T>().swap(scratch);
}

/// Calls release_if_large on each array when the scope ends, whichever way it ends.
template <class... Arrays>
class ReleaseIfLarge {
public:
    explicit ReleaseIfLarge(Arrays&... arrays) : arrays_(arrays...) {}
    ~ReleaseIfLarge() {
        std::apply([](auto&... array) { (release_if_large(array), ...); }, arrays_);
    }
    ReleaseIfLarge(const ReleaseIfLarge&) = delete;
    ReleaseIfLarge& operator=(const ReleaseIfLarge&) = delete;

private:
    std::tuple<Arrays&...> arrays_;
};

}  // namespace hbvh::detail
