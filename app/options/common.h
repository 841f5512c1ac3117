// Small options several commands share, each with the command's own default and limits: --spp,
// --reference-spp, --shadow-cascades, --size, --visibility, --json, --repr.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "probecast/session/representation.h"

namespace probecast::app {

// --spp (samples per probe per update, or per pixel), with each command's own default and limit.
inline CLI::Option* addSppOption(CLI::App* cmd, uint32_t& spp,
                                 const std::string& what = "samples (paths) per probe per update",
                                 uint32_t max = 1u << 16) {
  return cmd->add_option("--spp", spp, what)->check(CLI::Range(1, static_cast<int>(max)));
}

// --reference-spp: samples per pixel of the reference images.
inline CLI::Option* addReferenceSppOption(CLI::App* cmd, uint32_t& spp, uint32_t max,
                                          const std::string& what = "samples per pixel of the reference") {
  return cmd->add_option("--reference-spp", spp, what)->check(CLI::Range(1, static_cast<int>(max)));
}

// --shadow-cascades N: orthographic layers per directional light (RasterOptions::shadowCascades).
inline CLI::Option* addShadowCascadesOption(CLI::App* cmd, uint32_t& cascades) {
  return cmd->add_option("--shadow-cascades", cascades, "shadow cascades per directional light (1 = one layer over the scene)")
      ->check(CLI::Range(1, 4));
}

// --size WxH, each in [min, max].
inline CLI::Option* addSizeOption(CLI::App* cmd, std::vector<uint32_t>& size, const std::string& what, uint32_t min,
                                  uint32_t max) {
  return cmd->add_option("--size", size, what)->delimiter('x')->expected(2)->check(CLI::Range(static_cast<int>(min), static_cast<int>(max)));
}

// --visibility on|off: probe visibility in the raster client (RasterOptions::visibility).
inline CLI::Option* addVisibilityOption(CLI::App* cmd, bool& visibility) {
  return cmd
      ->add_option_function<std::string>(
          "--visibility", [&visibility](const std::string& v) { visibility = v == "on"; },
          "raster client: weigh probes by visibility from depth moments (on) or plain trilinear (off)")
      ->check(CLI::IsMember({"on", "off"}));
}

// --msaa 1|2|4|8: multisample anti-aliasing in the raster client (RasterOptions::msaaSamples).
inline CLI::Option* addMsaaOption(CLI::App* cmd, uint32_t& samples) {
  return cmd
      ->add_option("--msaa", samples,
                   "raster client: multisample anti-aliasing, 1 (off), 2, 4 or 8 coverage samples per pixel, shaded "
                   "once per pixel")
      ->check(CLI::IsMember({1, 2, 4, 8}))
      ->capture_default_str();
}

// --anisotropy 1..16: texture taps along a pixel footprint's long axis (RasterOptions::anisotropy).
inline CLI::Option* addAnisotropyOption(CLI::App* cmd, uint32_t& taps) {
  return cmd
      ->add_option("--anisotropy", taps,
                   "raster client: textures are read from their mip levels over each pixel's footprint, with up to "
                   "this many taps along its long axis (1: isotropic)")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
}

// --msaa and --anisotropy: how the raster client anti-aliases edges and filters textures.
inline void addRasterFilterOptions(CLI::App* cmd, uint32_t& msaaSamples, uint32_t& anisotropy) {
  addMsaaOption(cmd, msaaSamples);
  addAnisotropyOption(cmd, anisotropy);
}

// --json FILE, required by every benchmark.
inline CLI::Option* addJsonOption(CLI::App* cmd, std::string& json) {
  return cmd->add_option("--json", json, "write the results as JSON here")->required();
}

// --repr (or another name) checked by the one representation parser; `allowFloat` admits "float"
// (probes as traced).
inline CLI::Option* addRepresentationOption(CLI::App* cmd, std::string& repr, const std::string& what,
                                            bool allowFloat = false, const std::string& name = "--repr") {
  return cmd->add_option(name, repr, what)->check(CLI::Validator(
      [allowFloat](std::string& value) { return session::checkRepresentation(value, allowFloat); },
      allowFloat ? "{float,l1,zh3h,zh3,l2,fp16}" : "{l1,zh3h,zh3,l2,fp16}"));
}

}  // namespace probecast::app
