// The one VK_CHECK: a failed Vulkan call is a platform failure, reported with its location.
#pragma once

#include <stdexcept>
#include <string>

#include <vulkan/vulkan.h>

namespace probecast::renderer {

[[noreturn]] void vkFail(VkResult result, const char* call, const char* file, int line);

}  // namespace probecast::renderer

#define VK_CHECK(call)                                                                         \
  do {                                                                                         \
    const VkResult vkCheckResult_ = (call);                                                    \
    if (vkCheckResult_ != VK_SUCCESS) ::probecast::renderer::vkFail(vkCheckResult_, #call, __FILE__, __LINE__); \
  } while (0)
