// Images on disk: linear float EXR for data, tone-mapped PNG for people.
#pragma once

#include <string>
#include <vector>

namespace probecast::imaging {

// EXR through OpenEXR. rgb: width × height × 3 linear floats, row-major from the top.
// writeExr writes R, G, B as 32-bit float, ZIP-compressed (lossless).
bool writeExr(const std::string& path, const std::vector<float>& rgb, int width, int height, std::string& error);
// readExr reads any compression (NO, RLE, ZIPS, ZIP, PIZ, PXR24, B44, B44A, DWAA, DWAB), scan lines
// or tiles (the top level), half, float or uint channels into floats:
// - R, G, B when any of them is present (a missing one reads 0); else Y as grey (R = G = B = Y), or
//   luminance/chroma (Y, RY, BY) converted to RGB; alpha and other channels are ignored (EXR colour
//   is premultiplied, so the colour is already what the pixel contributes).
// - The result covers the display window: data-window pixels outside it are dropped, display-window
//   pixels the data window lacks are 0. width/height are the display window's.
// Returns false with a message naming the file for a missing, corrupt, truncated or deep file, or
// one with no colour channel.
bool readExr(const std::string& path, std::vector<float>& rgb, int& width, int& height, std::string& error);
// Radiance .hdr (RGBE) as linear float RGB (stb_image).
bool readHdr(const std::string& path, std::vector<float>& rgb, int& width, int& height, std::string& error);
enum class ToneMap {
  Filmic,  // Narkowicz's fit of the ACES filmic curve (2015), then gamma 2.2: highlights roll off
  Gamma,   // plain gamma 2.2, clamped: what the metrics see, minus the clamp
};
// A PNG for people to look at: exposure, tone map, 8 bits (not for metrics: use the EXR).
bool writePngPreview(const std::string& path, const std::vector<float>& rgb, int width, int height, float exposure,
                     std::string& error, ToneMap toneMap = ToneMap::Filmic);
// "filmic" or "gamma".
bool parseToneMap(const std::string& name, ToneMap& out);
// The 8-bit pixels writePngPreview writes, as RGBA (alpha 255): what a window shows.
std::vector<unsigned char> toneMapRgba8(const std::vector<float>& rgb, float exposure, ToneMap toneMap = ToneMap::Filmic);
// An 8-bit RGBA image as a PNG (alpha dropped).
bool writePngRgba(const std::string& path, const std::vector<unsigned char>& rgba, int width, int height,
                  std::string& error);
// One line of text drawn into an RGBA image at (x, y) (its top left, pixels) in `rgb` (each glyph
// pixel `scale` × `scale`), on a dark band across the whole width behind it; clipped to the image.
// Returns the band's height in pixels.
int drawTextLine(std::vector<unsigned char>& rgba, int width, int height, int x, int y, const std::string& text,
                 int scale = 2, const unsigned char rgb[3] = nullptr);

}  // namespace probecast::imaging
