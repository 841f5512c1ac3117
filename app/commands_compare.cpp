// `probecast compare A.exr B.exr`: PSNR and SSIM after gamma 2.2, and a false-colour difference.
// Images holding NaN or infinite pixels are refused with their count and first position.
#include <fmt/format.h>

#include "commands.h"
#include "probecast/imaging/image_io.h"
#include "probecast/imaging/image_metrics.h"

namespace probecast::app {

void addCompareCommand(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("compare", "PSNR and SSIM of an image against a reference (both EXR)");
  struct Options {
    std::string test, reference, diff, json;
    double scale = 0.1;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("image", o->test, "image to judge (EXR, linear)")->required()->check(CLI::ExistingFile);
  cmd->add_option("reference", o->reference, "reference (EXR, linear)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--diff", o->diff, "write a false-colour PNG of the luminance difference");
  cmd->add_option("--diff-scale", o->scale, "difference (after gamma) shown as full red")->check(CLI::Range(1e-6, 10.0));
  cmd->add_option("--json", o->json, "write the metrics as JSON here");
  cmd->callback([o] {
    std::vector<float> a, b;
    int wa = 0, ha = 0, wb = 0, hb = 0;
    std::string error;
    if (!imaging::readExr(o->test, a, wa, ha, error) || !imaging::readExr(o->reference, b, wb, hb, error))
      throw std::runtime_error(error);
    if (wa != wb || ha != hb)
      throw std::runtime_error(fmt::format("sizes differ: {}x{} against {}x{}", wa, ha, wb, hb));
    // A NaN or infinite pixel has no place in PSNR or SSIM: name the images and refuse, rather
    // than score it as black.
    std::string bad;
    for (const auto& [path, rgb] : {std::pair{&o->test, &a}, std::pair{&o->reference, &b}}) {
      const imaging::NonFinitePixels nf = imaging::findNonFinitePixels(*rgb);
      if (nf.count > 0)
        bad += fmt::format("{}{}: {} non-finite pixels (NaN or infinite; the first at x {}, y {})", bad.empty() ? "" : "; ",
                           *path, nf.count, nf.first % static_cast<size_t>(wa), nf.first / static_cast<size_t>(wa));
    }
    if (!bad.empty()) throw std::runtime_error(bad + "; not comparing: the metrics would be meaningless");
    const imaging::ImageMetrics m = imaging::compareImages(a, b, wa, ha);
    fmt::print("PSNR {:.2f} dB, SSIM {:.4f} (both after plain gamma 2.2, no clamping; SSIM on luminance)\n", m.psnrDb,
               m.ssim);
    if (!o->diff.empty()) {
      orThrow(imaging::writeDifferencePng(o->diff, a, b, wa, ha, o->scale, error), error);
      fmt::print("wrote {}\n", o->diff);
    }
    if (!o->json.empty()) {
      writeTextFile(o->json, fmt::format("{{\"command\": \"{}\", \"psnr_db\": {}, \"ssim\": {}, \"mse\": {}}}\n",
                                         commandLine(), std::isinf(m.psnrDb) ? "null" : fmt::format("{}", m.psnrDb),
                                         m.ssim, m.mse));
      fmt::print("wrote {}\n", o->json);
    }
  });
}

}  // namespace probecast::app
