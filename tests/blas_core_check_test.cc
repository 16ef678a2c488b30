#include "plugin/blas_core_check.h"

#include <gtest/gtest.h>

namespace taut {
namespace {

const CpuVectorSupport kSse{false, false};
const CpuVectorSupport kAvx2{true, false};
const CpuVectorSupport kAvx512{true, true};

TEST(BlasCoreCheckTest, CoreTypeFollowsTheWidestVectorExtension) {
  EXPECT_EQ(ChooseOpenBlasCoreType(kAvx512), "SkylakeX");
  EXPECT_EQ(ChooseOpenBlasCoreType(kAvx2), "Haswell");
  EXPECT_EQ(ChooseOpenBlasCoreType(kSse), "");
}

TEST(BlasCoreCheckTest, WarnsOnlyForTheGenericCoreOnAVectorCpu) {
  const std::string avx512 = FormatOpenBlasCoreWarning("Prescott", kAvx512);
  EXPECT_NE(avx512.find("OPENBLAS_CORETYPE=SkylakeX"), std::string::npos) << avx512;
  const std::string avx2 = FormatOpenBlasCoreWarning("Prescott", kAvx2);
  EXPECT_NE(avx2.find("OPENBLAS_CORETYPE=Haswell"), std::string::npos) << avx2;
  // Generic kernels are all an SSE-only CPU has; a detected core is left alone.
  EXPECT_EQ(FormatOpenBlasCoreWarning("Prescott", kSse), "");
  for (const char* core : {"SkylakeX", "Cooperlake", "Haswell", "Zen", ""})
    EXPECT_EQ(FormatOpenBlasCoreWarning(core, kAvx512), "") << core;
}

TEST(BlasCoreCheckTest, WarningStateIsStableAcrossCalls) {
  // Whatever this machine's BLAS, the start-up answer is the one later calls give.
  const bool first = WarnOnceIfOpenBlasCoreIsGeneric();
  EXPECT_EQ(WarnOnceIfOpenBlasCoreIsGeneric(), first);
  EXPECT_EQ(first,
            !FormatOpenBlasCoreWarning(GetOpenBlasCoreName(), DetectCpuVectorSupport()).empty());
}

}  // namespace
}  // namespace taut
