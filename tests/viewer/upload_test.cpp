// uploadBuffer's fill (vulkan/buffers.h) on lavapipe with the validation layer: into memory the
// CPU caches it writes the target in place, and into write-combined memory (a discrete GPU's BAR,
// forced here) through a cached bounce block, the same bytes either way, whatever the grain.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

#include "vulkan/buffers.h"
#include "vulkan/context.h"

namespace dpoint {
namespace {

// Element k of the upload: `grain` bytes that name it, so a piece written at the wrong offset or
// with the wrong length shows.
void fillElements(void* dst, VkDeviceSize offset, VkDeviceSize bytes, VkDeviceSize grain) {
  ASSERT_EQ(offset % grain, 0u);
  auto* out = static_cast<uint8_t*>(dst);
  for (VkDeviceSize i = 0; i < bytes; ++i) {
    const uint64_t k = (offset + i) / grain, at = (offset + i) % grain;
    out[i] = static_cast<uint8_t>(k * 131 + at * 7 + (k >> 8));
  }
}

TEST(Upload, bouncedAndInPlaceFillsWriteTheSameBytes) {
  ContextOptions options{"cpu", true};
  Result<std::unique_ptr<VulkanContext>> created = VulkanContext::create(options);
  ASSERT_TRUE(created.ok()) << created.error().message;
  const VulkanContext& context = **created;
  // Three 1 MiB pieces and more, an element that does not divide 64 KiB, a short last element run.
  for (VkDeviceSize grain : {VkDeviceSize{1}, VkDeviceSize{4}, VkDeviceSize{24}}) {
    const VkDeviceSize size = (VkDeviceSize{3} << 20) + 1000 * grain;
    std::vector<uint8_t> expected(size);
    fillElements(expected.data(), 0, size, grain);
    for (bool bounce : {false, true}) {
      Result<Buffer> target = createUploadTarget(context, size + 64, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "a test");
      ASSERT_TRUE(target.ok()) << target.error().message;
      ASSERT_NE(target->mapped, nullptr);
      // lavapipe's memory is the process's heap, cached: the fill writes it in place.
      EXPECT_FALSE(target->write_combined);
      target->write_combined = bounce;
      std::memset(target->mapped, 0xEE, size + 64);
      ASSERT_TRUE(uploadBuffer(context, *target, size,
                               [&](void* dst, VkDeviceSize offset, VkDeviceSize bytes) {
                                 fillElements(dst, offset, bytes, grain);
                               },
                               grain, VkDeviceSize{32} << 20, 32)
                      .ok());
      const auto* got = static_cast<const uint8_t*>(target->mapped);
      EXPECT_EQ(std::memcmp(got + 32, expected.data(), size), 0) << "grain " << grain << ", bounce " << bounce;
      for (VkDeviceSize i : {VkDeviceSize{0}, VkDeviceSize{31}, size + 32, size + 63})
        EXPECT_EQ(got[i], 0xEE) << "byte " << i << " outside the upload, grain " << grain << ", bounce " << bounce;
      destroyBuffer(context, *target);
    }
  }
  for (const std::string& m : context.validationMessages()) ADD_FAILURE() << m;
}

}  // namespace
}  // namespace dpoint
