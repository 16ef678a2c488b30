// The row types of an island, in one table: name (StepStats counter and CSV column "rows_<name>"),
// the unit of C, and whether C is a fraction of a limit.
#pragma once

#include <array>
#include <cstdint>

namespace taut {

// What a row constrains, for statistics.
enum class RowType : std::uint8_t {
  kStrainLimit,
  kEnergyLimit,
  kContact,       // deformable against rigid or deformable (normal and friction rows)
  kRigidContact,  // Bullet's rigid-rigid contact inside a deformable island
  kJoint,         // Bullet joint rows and node attachments (bilateral)
  kNodeHeight,    // a free deformable node above a world height z_min (NodeHeightSource)
};
constexpr int kNumRowTypes = 6;

struct RowTypeInfo {
  RowType type;
  const char* name;    // "strain", ...: StepStats::rows_<name>, the CSV column rows_<name>
  const char* c_unit;  // unit of the row's C (violations are max(0, -C) in this unit)
  bool is_limit;       // C a fraction of a limit; else a distance, scaled in the violation figures
};

// Indexed by RowType (kRowTypes[static_cast<int>(t)].type == t, tests/row_types_test.cc).
inline constexpr std::array<RowTypeInfo, kNumRowTypes> kRowTypes{{
    {RowType::kStrainLimit, "strain", "- (1 - |s_i - 1| / d_eff: 1 at rest, 0 at the limit)", true},
    {RowType::kEnergyLimit, "energy", "- (1 - U_e / U_max: 1 at rest, 0 at the limit)", true},
    {RowType::kContact, "contact", "m (gap along the normal)", false},
    {RowType::kRigidContact, "rigid_contact", "m (Bullet's contact distance)", false},
    {RowType::kJoint, "joint", "m or rad (Bullet's joint error)", false},
    {RowType::kNodeHeight, "node_height", "m (node height z_i - z_min)", false},
}};

inline const RowTypeInfo& GetRowTypeInfo(RowType type) { return kRowTypes[static_cast<int>(type)]; }

}  // namespace taut
