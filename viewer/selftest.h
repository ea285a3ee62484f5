// Start-up self-test of the emulated-double building blocks (DESIGN §4): a compute shader runs
// two-sum, split two-prod and a double-float add from shaders/render/df64.glsl on inputs read from a
// buffer. A compiler that reassociates or fuses despite `precise` returns zero low parts; rte and
// df64 are then unusable on that device, and saying so beats drawing a wrong picture.
#pragma once

#include <string>

#include "vulkan/context.h"
#include "viewer/encode.h"

namespace dpoint {

struct SelfTest {
  bool low_parts_survive = false;
  std::string detail;  // the values seen, for the message and `dpoint devices`
};

Result<SelfTest> runPrecisionSelfTest(const VulkanContext& context);

// Whether `mode` can run on the context's device, with the reason when not (kNoDevice): the
// device feature its row needs (native: shaderFloat64); emulated double (rte, df64) needs the
// self-test to pass; the probe needs vertexPipelineStoresAndAtomics.
Status modeUsable(const VulkanContext& context, PrecisionMode mode, const SelfTest& self_test, bool probe);

}  // namespace dpoint
