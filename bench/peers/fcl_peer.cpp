// SPDX-License-Identifier: MIT
// The FCL peer: one DynamicAABBTreeCollisionManager per copy, queried manager-against-manager.
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/capsule.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision.h>

#include <algorithm>

#include "peer.hpp"
#include "query/sort_pairs.hpp"

namespace hbvh::peers {
namespace {

fcl::Transform3d to_fcl(const RigidTransform& t) {
    fcl::Transform3d out = fcl::Transform3d::Identity();
    out.linear() = t.rotation;
    out.translation() = t.translation;
    return out;
}

/// Which copy and which primitive an object is; stored as the object's user data.
struct Tag {
    bool copy_b = false;
    std::uint32_t index = 0;
};

struct CallbackData {
    PairList* pairs = nullptr;
    fcl::CollisionRequestd request;  // defaults: one contact, no contact details: a yes/no answer
};

bool record_pair(fcl::CollisionObjectd* first, fcl::CollisionObjectd* second, void* user) {
    auto& data = *static_cast<CallbackData*>(user);
    fcl::CollisionResultd result;
    if (fcl::collide(first, second, data.request, result) > 0) {
        const auto* tag_first = static_cast<const Tag*>(first->getUserData());
        const auto* tag_second = static_cast<const Tag*>(second->getUserData());
        if (tag_first->copy_b) std::swap(tag_first, tag_second);
        data.pairs->emplace_back(tag_first->index, tag_second->index);
    }
    return false;  // never stop early: we want every pair
}

double tree_cost(const fcl::detail::NodeBase<fcl::AABBd>* node) {
    if (node == nullptr || node->isLeaf()) return 0.0;
    return 2.0 * node->bv.volume() + tree_cost(node->children[0]) + tree_cost(node->children[1]);
}

class FclPeer final : public Peer {
public:
    explicit FclPeer(std::span<const Primitive> primitives) {
        // Copy a is built first and alone, so its build time is one object's set-up.
        const auto start = std::chrono::steady_clock::now();
        build_copy(primitives, 0);
        build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        build_copy(primitives, 1);
    }

    /// One copy's objects and manager (copy 1 is copy b).
    void build_copy(std::span<const Primitive> primitives, int copy) {
        for (std::uint32_t i = 0; i < primitives.size(); ++i) {
            const LocalShape shape = to_local_shape(primitives[i].volume);
            std::shared_ptr<fcl::CollisionGeometryd> geometry;
            switch (shape.kind) {
                case LocalShape::Kind::box: geometry = std::make_shared<fcl::Boxd>(2.0 * shape.half_extents); break;
                case LocalShape::Kind::sphere: geometry = std::make_shared<fcl::Sphered>(shape.radius); break;
                case LocalShape::Kind::capsule:
                    geometry = std::make_shared<fcl::Capsuled>(shape.radius, shape.length);
                    break;
            }
            auto object = std::make_unique<fcl::CollisionObjectd>(geometry, to_fcl(shape.frame));
            tags_[copy].push_back({copy == 1, i});
            locals_[copy].push_back(to_fcl(shape.frame));
            objects_[copy].push_back(std::move(object));
        }
        // Tags are final now (no more push_back), so their addresses are stable.
        std::vector<fcl::CollisionObjectd*> raw;
        for (std::size_t i = 0; i < objects_[copy].size(); ++i) {
            objects_[copy][i]->setUserData(&tags_[copy][i]);
            objects_[copy][i]->computeAABB();
            raw.push_back(objects_[copy][i].get());
        }
        managers_[copy].registerObjects(raw);
        managers_[copy].setup();
    }

    void set_pose(const RigidTransform& pose_b) override {
        // FCL has no compound: every primitive of copy b is its own object and must be moved, its
        // AABB recomputed, and the manager's tree refitted.
        const fcl::Transform3d pose = to_fcl(pose_b);
        for (std::size_t i = 0; i < objects_[1].size(); ++i) {
            objects_[1][i]->setTransform(pose * locals_[1][i]);
            objects_[1][i]->computeAABB();
        }
        managers_[1].update();
    }

    void collide(PairList& pairs) override {
        pairs.clear();
        CallbackData data;
        data.pairs = &pairs;
        managers_[0].collide(&managers_[1], &data, record_pair);
        // Sorted as hbvh's queries sort theirs, so that no method is timed with a slower sort than another.
        hbvh::detail::sort_pairs(pairs, static_cast<std::uint32_t>(objects_[0].size()),
                                 static_cast<std::uint32_t>(objects_[1].size()));
        pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    }

    [[nodiscard]] double build_seconds() const override { return build_seconds_; }
    [[nodiscard]] double cost() const override { return tree_cost(managers_[0].getTree().getRoot()); }

private:
    std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects_[2];
    std::vector<fcl::Transform3d> locals_[2];
    std::vector<Tag> tags_[2];
    fcl::DynamicAABBTreeCollisionManagerd managers_[2];
    double build_seconds_ = 0.0;
};

}  // namespace

std::unique_ptr<Peer> make_fcl_peer(std::span<const Primitive> primitives) {
    return std::make_unique<FclPeer>(primitives);
}

}  // namespace hbvh::peers
