#include "probecast/renderer/looking_glass.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <algorithm>
#include <string>
#include <vector>

#include "looking_glass.comp.h"
#include "looking_glass_calibration.h"
#include "vk_resources.h"

namespace probecast::renderer {
namespace {

constexpr int kShaderCells = 4;  // no cell pattern reaches past cell 3

// Mirrors the push-constant block of shaders/looking_glass.comp (std430: the uvec4 at offset 32;
// 112 bytes, within the 128 every Vulkan device offers).
struct LookingGlassPush {
  int32_t screen[2];
  int32_t tile[2];
  int32_t columns;
  int32_t rows;
  int32_t views;
  uint32_t flags;
  uint32_t phase[4];
  int32_t bandTop;    // this pass's tile rows of the quilt (from its top) and pixel rows of the panel
  int32_t bandRows;
  int32_t panelTop;
  int32_t panelRows;
  uint32_t cellPhase[kShaderCells * 3];  // per cell, per subpixel: its offset's phase
};
static_assert(sizeof(LookingGlassPush) == 112 && offsetof(LookingGlassPush, phase) == 32 &&
              offsetof(LookingGlassPush, cellPhase) == 64);
constexpr uint32_t kInvView = 1, kFlipX = 2, kFlipY = 4;
constexpr uint32_t kPatternShift = 3, kCellCountShift = 6;  // 3 bits each in flags

// A phase in lenticules as an unsigned 0.32 fixed-point fraction (its integer part dropped).
uint32_t fixedTurns(double turns) {
  const double fraction = turns - std::floor(turns);
  const double scaled = std::round(fraction * 4294967296.0);
  return scaled >= 4294967296.0 ? 0u : static_cast<uint32_t>(scaled);
}

// Everything the interleaving dispatch creates, released in reverse order however it ends.
struct InterleavePass {
  VulkanDevice& d;
  Buffer quilt, panel;
  VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;

  explicit InterleavePass(VulkanDevice& device) : d(device) {}
  InterleavePass(const InterleavePass&) = delete;
  InterleavePass& operator=(const InterleavePass&) = delete;
  ~InterleavePass() {
    if (pool) vkDestroyDescriptorPool(d.device, pool, nullptr);
    if (pipeline) vkDestroyPipeline(d.device, pipeline, nullptr);
    if (layout) vkDestroyPipelineLayout(d.device, layout, nullptr);
    if (setLayout) vkDestroyDescriptorSetLayout(d.device, setLayout, nullptr);
    destroyBuffer(d, panel);
    destroyBuffer(d, quilt);
  }
};

}  // namespace

namespace {

// Runs of whole units (tile rows of the quilt, pixel rows of the panel), each at most `limit` bytes.
struct Band {
  uint32_t first = 0, count = 0;
};
std::vector<Band> splitIntoBands(uint32_t units, VkDeviceSize unitBytes, VkDeviceSize limit, const std::string& what) {
  if (unitBytes > limit)
    throw std::runtime_error("interleaveQuilt: one " + what + " (" + std::to_string(unitBytes) +
                             " bytes) exceeds the device's storage-buffer limit of " + std::to_string(limit) + " bytes");
  const auto per = static_cast<uint32_t>(std::min<VkDeviceSize>(units, limit / unitBytes));
  std::vector<Band> bands;
  for (uint32_t first = 0; first < units; first += per) bands.push_back({first, std::min(per, units - first)});
  return bands;
}

void checkQuilt(const Image& quilt, int columns, int rows, const LookingGlassCalibration& cal) {
  const std::string where = "interleaveQuilt: ";
  if (columns < 1 || rows < 1)
    throw std::invalid_argument(where + "the quilt layout must be at least 1 × 1 (got " + std::to_string(columns) +
                                " × " + std::to_string(rows) + ")");
  const uint32_t cols = static_cast<uint32_t>(columns), rws = static_cast<uint32_t>(rows);
  if (quilt.width < cols || quilt.height < rws || quilt.width % cols != 0 || quilt.height % rws != 0)
    throw std::invalid_argument(where + "a " + std::to_string(quilt.width) + " × " + std::to_string(quilt.height) +
                                " quilt does not split into " + std::to_string(columns) + " × " +
                                std::to_string(rows) + " equal tiles");
  if (quilt.rgb.size() != static_cast<size_t>(quilt.width) * quilt.height * 3)
    throw std::invalid_argument(where + "the quilt holds " + std::to_string(quilt.rgb.size()) + " floats, not " +
                                std::to_string(static_cast<size_t>(quilt.width) * quilt.height * 3));
  checkLookingGlassCalibration(cal, where + "calibration ");
}

// The subpixels' phases within their pixel, per cell: a row of subpixels a third of a pixel apart
// (one cell) unless the calibration places them in cells.
void setCellPhases(LookingGlassPush& push, const LookingGlassCalibration& cal, double pitchEff, double tilt) {
  const double w = cal.screenW, h = cal.screenH;
  std::vector<LookingGlassSubpixelCell> cells = cal.subpixelCells;
  int pattern = cal.cellPatternMode;
  if (cells.empty()) {
    LookingGlassSubpixelCell row;
    for (int i = 0; i < 3; ++i) row.dx[i] = (cal.flipSubp ? -1.0 : 1.0) * i / 3.0;
    cells.push_back(row);
    pattern = 0;
  }
  // Patterns index cells 0..3, taken modulo the count: with four or more, only the first four.
  const int count = std::min<int>(kShaderCells, static_cast<int>(cells.size()));
  for (int c = 0; c < count; ++c)
    for (int i = 0; i < 3; ++i)
      push.cellPhase[c * 3 + i] = fixedTurns((cells[c].dx[i] / w + cells[c].dy[i] / h * tilt) * pitchEff);
  push.flags |= static_cast<uint32_t>(pattern) << kPatternShift | static_cast<uint32_t>(count) << kCellCountShift;
}

// The push constants of every pass but its bands: the lens phase per pixel step right, per pixel
// step up, per subpixel of each cell, and at pixel (0, 0) (its centre), in double precision
// before the shader's fixed-point arithmetic.
LookingGlassPush interleavePush(const Image& quilt, int columns, int rows, const LookingGlassCalibration& cal) {
  const double w = cal.screenW, h = cal.screenH, slope = cal.slope;
  const double pitchEff = cal.pitch * w / cal.dpi * std::cos(std::atan(1.0 / slope));
  const double tilt = h / (w * slope);
  const double perX = pitchEff / w, perY = pitchEff * tilt / h;
  LookingGlassPush push{};
  push.screen[0] = cal.screenW;
  push.screen[1] = cal.screenH;
  push.tile[0] = static_cast<int32_t>(quilt.width / static_cast<uint32_t>(columns));
  push.tile[1] = static_cast<int32_t>(quilt.height / static_cast<uint32_t>(rows));
  push.columns = columns;
  push.rows = rows;
  push.views = columns * rows;
  push.flags = (cal.invView ? kInvView : 0u) | (cal.flipImageX ? kFlipX : 0u) | (cal.flipImageY ? kFlipY : 0u);
  push.phase[0] = fixedTurns(perX);
  push.phase[1] = fixedTurns(perY);
  push.phase[3] = fixedTurns(0.5 * perX + 0.5 * perY - cal.center);
  setCellPhases(push, cal, pitchEff, tilt);
  return push;
}

// The compute pipeline and its one descriptor set over the pass's two buffers.
void createInterleavePipeline(InterleavePass& pass) {
  VulkanDevice& d = pass.d;
  VkDescriptorSetLayoutBinding bindings[2] = {};
  for (uint32_t b = 0; b < 2; ++b) {
    bindings[b].binding = b;
    bindings[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[b].descriptorCount = 1;
    bindings[b].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  VkDescriptorSetLayoutCreateInfo lci{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  lci.bindingCount = 2;
  lci.pBindings = bindings;
  VK_CHECK(vkCreateDescriptorSetLayout(d.device, &lci, nullptr, &pass.setLayout));
  pass.layout = createPipelineLayout(d, pass.setLayout, VK_SHADER_STAGE_COMPUTE_BIT, sizeof(LookingGlassPush));
  VkComputePipelineCreateInfo pci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  pci.stage = VkPipelineShaderStageCreateInfo{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  pci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  pci.stage.module = createShaderModule(d, kLookingGlassComp, sizeof kLookingGlassComp);
  pci.stage.pName = "main";
  pci.layout = pass.layout;
  const VkResult created = vkCreateComputePipelines(d.device, VK_NULL_HANDLE, 1, &pci, nullptr, &pass.pipeline);
  vkDestroyShaderModule(d.device, pci.stage.module, nullptr);
  VK_CHECK(created);
  const VkDescriptorPoolSize sizes[1] = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2}};
  createSingleDescriptorSet(d, pass.setLayout, sizes, 1, pass.pool, pass.set);
  const VkDescriptorBufferInfo infos[2] = {{pass.quilt.buffer, 0, VK_WHOLE_SIZE},
                                           {pass.panel.buffer, 0, VK_WHOLE_SIZE}};
  VkWriteDescriptorSet writes[2];
  for (uint32_t b = 0; b < 2; ++b) {
    writes[b] = VkWriteDescriptorSet{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[b].dstSet = pass.set;
    writes[b].dstBinding = b;
    writes[b].descriptorCount = 1;
    writes[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[b].pBufferInfo = &infos[b];
  }
  vkUpdateDescriptorSets(d.device, 2, writes, 0, nullptr);
}

void dispatchBand(InterleavePass& pass, const LookingGlassPush& push) {
  submitAndWait(pass.d, [&](VkCommandBuffer cmd) {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pass.pipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pass.layout, 0, 1, &pass.set, 0, nullptr);
    vkCmdPushConstants(cmd, pass.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
    vkCmdDispatch(cmd, static_cast<uint32_t>(push.screen[0] + 7) / 8, static_cast<uint32_t>(push.panelRows + 7) / 8, 1);
    // The fence alone does not make shader writes visible to the host: this barrier does.
    VkMemoryBarrier toHost{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    toHost.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
    toHost.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &toHost, 0,
                         nullptr, 0, nullptr);
  });
}

}  // namespace

Image interleaveQuilt(VulkanContext& context, const Image& quilt, int columns, int rows,
                      const LookingGlassCalibration& cal, uint64_t bufferLimit) {
  checkQuilt(quilt, columns, rows, cal);
  VulkanDevice& d = context.device();
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(d.physical, &props);
  const VkDeviceSize limit = bufferLimit ? std::min<VkDeviceSize>(bufferLimit, props.limits.maxStorageBufferRange)
                                         : props.limits.maxStorageBufferRange;
  LookingGlassPush push = interleavePush(quilt, columns, rows, cal);
  // Bounded memory: the quilt goes up a band of tile rows at a time and the panel comes back a
  // band of pixel rows at a time, each within the device's storage-buffer range.
  const size_t quiltRowFloats = static_cast<size_t>(quilt.width) * static_cast<uint32_t>(push.tile[1]) * 3;
  const size_t panelRowFloats = static_cast<size_t>(cal.screenW) * 3;
  const std::vector<Band> quiltBands = splitIntoBands(static_cast<uint32_t>(rows), quiltRowFloats * sizeof(float),
                                                      limit, "row of quilt tiles");
  const std::vector<Band> panelBands = splitIntoBands(static_cast<uint32_t>(cal.screenH),
                                                      panelRowFloats * sizeof(float), limit, "panel row");
  InterleavePass pass(d);
  pass.quilt = createBuffer(d, quiltBands.front().count * quiltRowFloats * sizeof(float),
                            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  pass.panel = createBuffer(d, panelBands.front().count * panelRowFloats * sizeof(float),
                            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  createInterleavePipeline(pass);
  Image out;
  out.width = static_cast<uint32_t>(cal.screenW);
  out.height = static_cast<uint32_t>(cal.screenH);
  out.rgb.resize(static_cast<size_t>(out.width) * out.height * 3);
  for (const Band& p : panelBands) {
    push.panelTop = static_cast<int32_t>(p.first);
    push.panelRows = static_cast<int32_t>(p.count);
    for (const Band& q : quiltBands) {
      std::memcpy(pass.quilt.mapped, quilt.rgb.data() + q.first * quiltRowFloats, q.count * quiltRowFloats * sizeof(float));
      push.bandTop = static_cast<int32_t>(q.first);
      push.bandRows = static_cast<int32_t>(q.count);
      dispatchBand(pass, push);
    }
    std::memcpy(out.rgb.data() + p.first * panelRowFloats, pass.panel.mapped, p.count * panelRowFloats * sizeof(float));
  }
  return out;
}

}  // namespace probecast::renderer
