// SPDX-License-Identifier: MIT
// The Bullet peer: a btCompoundShape per object, queried compound-against-compound via the dispatcher.
#include <btBulletCollisionCommon.h>
#include <BulletCollision/CollisionDispatch/btCollisionObjectWrapper.h>

#include <algorithm>

#include "peer.hpp"
#include "query/sort_pairs.hpp"

namespace hbvh::peers {
namespace {

btVector3 to_bt(const Vec3& v) { return {v.x(), v.y(), v.z()}; }

btTransform to_bt(const RigidTransform& t) {
    const Mat3& r = t.rotation;
    const btMatrix3x3 basis(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2));
    return btTransform(basis, to_bt(t.translation));
}

/// Records the child indices of every contact with depth <= 0. Bullet also reports points up to its
/// contact breaking threshold (separated by a little); those are not overlaps, so they are dropped.
class PairRecorder : public btManifoldResult {
public:
    PairRecorder(const btCollisionObjectWrapper* a, const btCollisionObjectWrapper* b, const btCollisionObject* object_a,
                 PairList& pairs)
        : btManifoldResult(a, b), object_a_(object_a), pairs_(pairs) {}

    void addContactPoint(const btVector3&, const btVector3&, btScalar depth) override {
        if (depth > 0.0) return;
        // The compound algorithm points m_body0Wrap / m_body1Wrap at the two child wrappers, whose
        // m_index is the child index; which of them belongs to copy a depends on any swapping inside.
        const btCollisionObjectWrapper* first = m_body0Wrap;
        const btCollisionObjectWrapper* second = m_body1Wrap;
        if (first->getCollisionObject() != object_a_) std::swap(first, second);
        pairs_.emplace_back(static_cast<std::uint32_t>(first->m_index), static_cast<std::uint32_t>(second->m_index));
    }

private:
    const btCollisionObject* object_a_;
    PairList& pairs_;
};

double dbvt_cost(const btDbvtNode* node) {
    if (node == nullptr || node->isleaf()) return 0.0;
    const btVector3 extent = node->volume.Maxs() - node->volume.Mins();
    return 2.0 * extent.x() * extent.y() * extent.z() + dbvt_cost(node->childs[0]) + dbvt_cost(node->childs[1]);
}

class BulletPeer final : public Peer {
public:
    explicit BulletPeer(std::span<const Primitive> primitives)
        : dispatcher_(&configuration_), compound_(/*enableDynamicAabbTree=*/true, static_cast<int>(primitives.size())) {
        const auto start = std::chrono::steady_clock::now();
        children_.reserve(primitives.size());
        for (const Primitive& primitive : primitives) {
            const LocalShape shape = to_local_shape(primitive.volume);
            std::unique_ptr<btConvexShape> child;
            switch (shape.kind) {
                case LocalShape::Kind::box: child = std::make_unique<btBoxShape>(to_bt(shape.half_extents)); break;
                case LocalShape::Kind::sphere: child = std::make_unique<btSphereShape>(shape.radius); break;
                case LocalShape::Kind::capsule:
                    child = std::make_unique<btCapsuleShapeZ>(shape.radius, shape.length);
                    break;
            }
            // A box's margin is carved out of its extents and added back, so 0 keeps it exact and
            // stops GJK from rounding its corners; spheres and capsules keep their radius as margin
            // (Bullet ignores setMargin for them: the radius is the margin).
            if (shape.kind == LocalShape::Kind::box) child->setMargin(0.0);
            compound_.addChildShape(to_bt(shape.frame), child.get());
            children_.push_back(std::move(child));
        }
        compound_.setMargin(0.0);
        build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        object_a_.setCollisionShape(&compound_);
        object_b_.setCollisionShape(&compound_);
        object_a_.setWorldTransform(btTransform::getIdentity());
        object_b_.setWorldTransform(btTransform::getIdentity());
        const btCollisionObjectWrapper wrap_a(nullptr, &compound_, &object_a_, object_a_.getWorldTransform(), -1, -1);
        const btCollisionObjectWrapper wrap_b(nullptr, &compound_, &object_b_, object_b_.getWorldTransform(), -1, -1);
        algorithm_ = dispatcher_.findAlgorithm(&wrap_a, &wrap_b, nullptr, BT_CONTACT_POINT_ALGORITHMS);
    }

    ~BulletPeer() override {
        if (algorithm_ != nullptr) {
            algorithm_->~btCollisionAlgorithm();
            dispatcher_.freeCollisionAlgorithm(algorithm_);
        }
    }
    BulletPeer(const BulletPeer&) = delete;
    BulletPeer& operator=(const BulletPeer&) = delete;

    void set_pose(const RigidTransform& pose_b) override { object_b_.setWorldTransform(to_bt(pose_b)); }

    void collide(PairList& pairs) override {
        pairs.clear();
        const btCollisionObjectWrapper wrap_a(nullptr, &compound_, &object_a_, object_a_.getWorldTransform(), -1, -1);
        const btCollisionObjectWrapper wrap_b(nullptr, &compound_, &object_b_, object_b_.getWorldTransform(), -1, -1);
        PairRecorder recorder(&wrap_a, &wrap_b, &object_a_, pairs);
        algorithm_->processCollision(&wrap_a, &wrap_b, dispatch_info_, &recorder);
        // Several contact points per child pair are normal (box-box gives up to 4). Sorted as hbvh's queries
        // sort theirs, so that no method is timed with a slower sort than another.
        const auto count = static_cast<std::uint32_t>(children_.size());
        hbvh::detail::sort_pairs(pairs, count, count);
        pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    }

    [[nodiscard]] double build_seconds() const override { return build_seconds_; }
    [[nodiscard]] double cost() const override { return dbvt_cost(compound_.getDynamicAabbTree()->m_root); }

private:
    btDefaultCollisionConfiguration configuration_;
    btCollisionDispatcher dispatcher_;
    btDispatcherInfo dispatch_info_;
    std::vector<std::unique_ptr<btConvexShape>> children_;
    btCompoundShape compound_;
    btCollisionObject object_a_;
    btCollisionObject object_b_;
    btCollisionAlgorithm* algorithm_ = nullptr;
    double build_seconds_ = 0.0;
};

}  // namespace

std::unique_ptr<Peer> make_bullet_peer(std::span<const Primitive> primitives) {
    return std::make_unique<BulletPeer>(primitives);
}

}  // namespace hbvh::peers
