// `probecast view --looking-glass`: a display's calibration picks the view set and view size, and
// the rendered views are interleaved for its panel (to files, or to a window).
#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "commands.h"
#include "view.h"

namespace probecast::app {

renderer::Image interleaved(renderer::VulkanContext& context, const std::vector<renderer::Image>& images,
                            const std::vector<renderer::ViewInfo>& views, const renderer::LookingGlassCalibration& lg) {
  return renderer::interleaveQuilt(context, renderer::composeQuilt(images, views, lg.quiltColumns, lg.quiltRows),
                                   lg.quiltColumns, lg.quiltRows, lg);
}

void showOnLookingGlass(FrameSource& source, renderer::VulkanContext& context,
                        const renderer::LookingGlassCalibration* lg) {
  if (!lg) return;
  source.compose = [&context, lg](const std::vector<renderer::Image>& images,
                                  const std::vector<renderer::ViewInfo>& views) {
    return interleaved(context, images, views, *lg);
  };
  source.displayWidth = static_cast<uint32_t>(lg->screenW);
  source.displayHeight = static_cast<uint32_t>(lg->screenH);
}

renderer::LookingGlassCalibration lookingGlassViewSet(ViewOptions& o, renderer::ViewSetSpec& spec) {
  renderer::LookingGlassCalibration lg = renderer::loadLookingGlassCalibration(o.lookingGlass);
  spec = {renderer::ViewSetSpec::Kind::HorizontalLightField, lg.quiltColumns, lg.quiltRows};
  o.views = fmt::format("lfh:{}x{}", lg.quiltColumns, lg.quiltRows);
  if (o.sizeOption->count() == 0) {  // the model's view height at the panel's aspect
    const auto height = static_cast<uint32_t>(lg.viewHeight);
    const auto width = static_cast<uint32_t>(std::lround(double(height) * lg.screenW / lg.screenH));
    o.size = {std::max<uint32_t>(1, width), height};
  }
  fmt::print("view: {} {} ({}x{}{}): {} views ({}x{} quilt) of {}x{} across {} degrees\n", lg.model,
             lg.serial.empty() ? std::string("(no serial)") : lg.serial, lg.screenW, lg.screenH,
             lg.subpixelCells.empty() ? "" : ", subpixel cells", spec.count(), spec.columns, spec.rows, o.size[0],
             o.size[1], lg.viewCone);
  return lg;
}

void writeLookingGlass(const ViewOptions& o, renderer::VulkanContext& context,
                       const std::vector<renderer::Image>& images, const std::vector<renderer::ViewInfo>& views,
                       const renderer::LookingGlassCalibration& lg) {
  const renderer::Image panel = interleaved(context, images, views, lg);
  const auto w = static_cast<int>(panel.width), h = static_cast<int>(panel.height);
  std::string error;
  orThrow(imaging::writePngPreview(o.out + "/looking_glass.png", panel.rgb, w, h, o.exposure, error, toneMapOf(o)) &&
              imaging::writeExr(o.out + "/looking_glass.exr", panel.rgb, w, h, error),
          error);
  fmt::print("view: wrote {}/looking_glass.png and .exr ({}x{}, interleaved for the panel)\n", o.out, w, h);
}

}  // namespace probecast::app
