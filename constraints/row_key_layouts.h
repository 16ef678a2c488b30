// The warm-start key layout of every row source, in one place: the fields below the 16-bit source
// id, most significant first, each with its width (constraints/row_key.h packs and checks them).
// The sources of a world have different ids, so keys of different sources never collide; within a
// source a layout is one to one on the values that fit.
#pragma once

#include "constraints/row_key.h"

namespace taut {

// StrainLimitSource: a row per element, limit axis, matched principal axis and bound.
inline constexpr RowKeyLayout<4> kStrainLimitRowKey{
    "strain limits",
    {{
        {"element", 31},        // element index (any int >= 0)
        {"axis", 2},            // limit axis j, 0-2; 3 = non-inversion floor (kStrainFloorAxis)
        {"principal axis", 2},  // matched material axis m = pi(i), 0-2
        {"bound", 1},           // StrainBound: 0 min, 1 max
    }}};

// The payload bits of kStrainLimitRowKey that name a row's principal direction (axis and principal
// axis, above the bound bit). Where two stretches are nearly equal the match of their directions
// to material axes can flip between iterates (docs/math.md §2.6, R3) while the row, its element
// and its bound stay: warm starts fall back to such a sibling key (IslandRows::OverwriteByKey).
inline constexpr std::uint64_t kStrainLimitDirectionBits = ((std::uint64_t{1} << 4) - 1) << 1;
// The payload bits of kStrainLimitRowKey below the element field.
inline constexpr std::uint64_t kStrainLimitElementShift = 5;

// EnergyLimitSource: a row per element (the element in the low bits: key = source | element).
inline constexpr RowKeyLayout<1> kEnergyLimitRowKey{
    "energy limits",
    {{
        {"element", 31},  // element index (any int >= 0)
    }}};

// DeformableContactSource: a contact point of one body against a surface triangle of the other
// (self-contact: direction 0, a boundary node against a triangle of the same body's boundary).
inline constexpr RowKeyLayout<4> kDeformableContactRowKey{
    "deformable contact",
    {{
        {"direction", 1},  // 0: points of A against triangles of B; 1: the reverse
        {"point", 22},     // contact point of the touching body, < 4,194,304
        {"triangle", 23},  // surface triangle of the other body, < 8,388,608
        {"row", 2},        // 0 normal, 1 and 2 the friction tangents
    }}};

// RigidContactSource: a contact point of a deformable against a rigid object.
inline constexpr RowKeyLayout<4> kRigidContactRowKey{
    "rigid contact",
    {{
        {"point", 22},         // contact point (or, for face rows, triangle), < 4,194,304
        {"outside world", 1},  // 0: object keyed by its world index; 1: an object in no world,
                               //    keyed by its position among the source's partners
        {"object", 22},        // the world index (getWorldArrayIndex) or position, < 4,194,304
        {"row", 3},            // 0 normal, 1 and 2 the friction tangents; 3-5 the same of a
                               // face contact (kRigidFaceRowOffset + row)
    }}};
// "row" field of a face contact's rows (a rigid shape against a boundary triangle): this plus
// 0 (normal), 1 or 2 (friction tangents).
inline constexpr int kRigidFaceRowOffset = 3;

// RigidManifoldSource: a point of Bullet's contact manifold between two rigid objects.
inline constexpr RowKeyLayout<4> kRigidManifoldRowKey{
    "rigid manifold",
    {{
        {"object a", 22},  // broadphase unique id of the manifold's body 0, < 4,194,304
        {"object b", 22},  // broadphase unique id of the manifold's body 1, < 4,194,304
        {"contact", 2},    // point index in the manifold (< MANIFOLD_CACHE_SIZE = 4)
        {"row", 2},        // 0 normal, 1 and 2 the friction tangents
    }}};

// JointSource: a row of a Bullet joint (btTypedConstraint::getInfo2).
inline constexpr RowKeyLayout<2> kJointRowKey{
    "joints",
    {{
        {"joint", 31},  // the joint's user constraint id (0 when unset)
        {"row", 17},    // the row's index among the island's joint rows of the step, < 131,072
    }}};

// NodeAttachmentSource: an attached node along one world axis.
inline constexpr RowKeyLayout<2> kNodeAttachmentRowKey{
    "node attachment",
    {{
        {"node", 31},  // position of the node in the attachment's node list
        {"axis", 2},   // world axis 0-2
    }}};

// NodeHeightSource: a free node above the body's height limit (one row per node).
inline constexpr RowKeyLayout<1> kNodeHeightRowKey{
    "node height",
    {{
        {"node", 31},  // node index in the body (any int >= 0)
    }}};

static_assert(kStrainLimitRowKey.bits() <= kRowKeyPayloadBits, "strain-limit key too wide");
static_assert(kStrainLimitRowKey.fields[1].bits + kStrainLimitRowKey.fields[2].bits +
                          kStrainLimitRowKey.fields[3].bits ==
                      kStrainLimitElementShift &&
                  kStrainLimitRowKey.fields[3].bits == 1,
              "kStrainLimitDirectionBits must follow kStrainLimitRowKey's layout");
static_assert(kEnergyLimitRowKey.bits() <= kRowKeyPayloadBits, "energy-limit key too wide");
static_assert(kDeformableContactRowKey.bits() <= kRowKeyPayloadBits, "contact key too wide");
static_assert(kRigidContactRowKey.bits() <= kRowKeyPayloadBits, "rigid-contact key too wide");
static_assert(kRigidManifoldRowKey.bits() <= kRowKeyPayloadBits, "manifold key too wide");
static_assert(kJointRowKey.bits() <= kRowKeyPayloadBits, "joint key too wide");
static_assert(kNodeAttachmentRowKey.bits() <= kRowKeyPayloadBits, "attachment key too wide");
static_assert(kNodeHeightRowKey.bits() <= kRowKeyPayloadBits, "node-height key too wide");

}  // namespace taut
