// The Python module `probecast`: the codec's records, temporal stream, SH projection, irradiance
// error metrics and probe files over numpy arrays.
//
// Inputs are taken without copying: arrays must already be C-contiguous with the stated dtype and
// shape, anything else is refused with ValueError (np.ascontiguousarray(x, np.float32) makes one).
// Loops over probes run without the GIL.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "probecast/codec/equirect.h"
#include "probecast/codec/irradiance_error.h"
#include "probecast/codec/probe_file.h"
#include "probecast/codec/probe_volume.h"
#include "probecast/codec/record.h"
#include "probecast/codec/sh.h"
#include "probecast/codec/status.h"
#include "probecast/codec/stream.h"
#ifdef PROBECAST_PYTHON_IMAGING
#include "probecast/imaging/image_io.h"
#endif

namespace py = pybind11;
using namespace probecast;

namespace {

const char* const kConventions =
    "Probes are 27 float32 per probe: real L2 spherical harmonics of incident radiance, without the "
    "Condon-Shortley phase, coefficient index i = l(l+1)+m in the order [00, 1-1, 10, 11, 2-2, 2-1, 20, 21, 22], "
    "coefficient-major RGB (probe[i*3 + channel]), direction (x, y, z) with z the SH pole.";

// Checks dtype, C-contiguity and shape (-1 = any) and returns the data pointer, without copying.
template <typename T>
const T* checkedData(const py::array& a, const char* what, std::initializer_list<py::ssize_t> shape) {
  if (!a.dtype().is(py::dtype::of<T>()))
    throw py::value_error(std::string(what) + ": expected dtype " + std::string(py::str(py::dtype::of<T>())) +
                          ", got " + std::string(py::str(a.dtype())));
  if (a.ndim() != static_cast<py::ssize_t>(shape.size()))
    throw py::value_error(std::string(what) + ": expected " + std::to_string(shape.size()) + " dimensions, got " +
                          std::to_string(a.ndim()));
  size_t d = 0;
  for (py::ssize_t s : shape) {
    if (s >= 0 && a.shape(static_cast<py::ssize_t>(d)) != s)
      throw py::value_error(std::string(what) + ": dimension " + std::to_string(d) + " must be " + std::to_string(s) +
                            ", got " + std::to_string(a.shape(static_cast<py::ssize_t>(d))));
    ++d;
  }
  if (!(a.flags() & py::array::c_style))
    throw py::value_error(std::string(what) + ": array must be C-contiguous (use numpy.ascontiguousarray)");
  return static_cast<const T*>(a.data());
}

// An output array: `out` when given (checked as checkedData does, and writable), else a new one.
template <typename T>
py::array_t<T> outputArray(const py::object& out, const char* what, py::ssize_t rows, py::ssize_t columns) {
  if (out.is_none()) return py::array_t<T>({rows, columns});
  if (!py::isinstance<py::array>(out)) throw py::value_error(std::string(what) + ": expected a numpy array");
  const py::array a = out.cast<py::array>();
  checkedData<T>(a, what, {rows, columns});
  if (!a.writeable()) throw py::value_error(std::string(what) + ": array is read-only");
  return out.cast<py::array_t<T>>();
}

Representation reprOf(const std::string& name) {
  auto r = parseRepresentation(name);
  if (!r) throw py::value_error("unknown representation '" + name + "' (expected l1, zh3h, zh3, l2 or fp16)");
  return *r;
}

py::array_t<float> probesArray(const float* data, size_t count) {
  py::array_t<float> out({static_cast<py::ssize_t>(count), static_cast<py::ssize_t>(kProbeFloats)});
  if (count) std::memcpy(out.mutable_data(), data, count * kProbeFloats * sizeof(float));
  return out;
}

py::array_t<uint8_t> maskArray(const uint8_t* data, size_t count) {
  py::array_t<uint8_t> out(static_cast<py::ssize_t>(count));
  if (count) std::memcpy(out.mutable_data(), data, count);
  return out;
}

StreamLayout layoutOf(const std::array<int, 3>& grid, const std::string& repr, int brick) {
  StreamLayout layout;
  for (int k = 0; k < 3; ++k) {
    if (grid[k] < 1 || grid[k] > kMaxGridDim)
      throw py::value_error("grid: every dimension must be 1.." + std::to_string(kMaxGridDim));
    layout.grid[k] = static_cast<uint16_t>(grid[k]);
  }
  if (brick < kMinBrickDim || brick > kMaxBrickDim)
    throw py::value_error("brick must be " + std::to_string(kMinBrickDim) + ".." + std::to_string(kMaxBrickDim));
  layout.brickDim = static_cast<uint8_t>(brick);
  layout.repr = reprOf(repr);
  if (!isValidLayout(layout)) throw py::value_error("grid too large (at most 2^24 probes)");
  return layout;
}

// Active flags: None (all active) or a C-contiguous uint8/bool array of one byte per probe.
const uint8_t* activeData(const py::object& active, uint32_t count, std::vector<uint8_t>& scratch) {
  if (active.is_none()) return nullptr;
  py::array a = py::array::ensure(active);
  if (!a) throw py::value_error("active: expected a numpy array of uint8 or bool");
  if (a.dtype().is(py::dtype::of<bool>())) {
    if (a.ndim() != 1 || a.shape(0) != count || !(a.flags() & py::array::c_style))
      throw py::value_error("active: expected a C-contiguous array of shape (" + std::to_string(count) + ",)");
    scratch.assign(static_cast<const uint8_t*>(a.data()), static_cast<const uint8_t*>(a.data()) + count);
    return scratch.data();
  }
  return checkedData<uint8_t>(a, "active", {static_cast<py::ssize_t>(count)});
}

struct PyStreamEncoder {
  StreamEncoder encoder;
  std::vector<uint8_t> frame;
  PyStreamEncoder(const std::array<int, 3>& grid, const std::string& repr, int brick, int deadzone, int zstdLevel,
                  bool compress, float errorBound)
      : encoder(layoutOf(grid, repr, brick), optionsFor(repr, deadzone, zstdLevel, compress, errorBound)) {}
  static EncoderOptions optionsFor(const std::string& repr, int deadzone, int zstdLevel, bool compress, float errorBound) {
    if (!(errorBound >= 0.0f && errorBound <= 10.0f)) throw py::value_error("error_bound: 0 (off) to 10");
    if (errorBound > 0.0f && brickRepresentations(reprOf(repr)).size() < 2)
      throw py::value_error("error_bound chooses among cheaper representations per brick: " + repr + " has none");
    EncoderOptions o{deadzone, zstdLevel, compress};
    o.errorBound = errorBound;
    return o;
  }
  uint32_t count() const { return probeCount(encoder.layout()); }
};

struct PyStreamDecoder {
  StreamDecoder decoder;
  PyStreamDecoder(const std::array<int, 3>& grid, const std::string& repr, int brick, bool zh3PerPixel)
      : decoder(layoutOf(grid, repr, brick)) {
    decoder.setZh3PerPixel(zh3PerPixel);
  }
  uint32_t count() const { return probeCount(decoder.layout()); }
};

py::object codecErrorType;
py::object codecStatusType;

}  // namespace

PYBIND11_MODULE(probecast, m) {
  m.doc() = std::string("probecast: light-probe codec (records, temporal stream, SH projection, irradiance error, "
                        "probe files) over numpy arrays.\n\n") +
            kConventions +
            "\nIrradiance is E(n) = sum_l A_l sum_m c_lm Y_lm(n) with A = (pi, 2pi/3, pi/4): not divided by pi, "
            "not clamped. Array inputs must be C-contiguous with the stated dtype (not copied); others raise ValueError.";

  codecErrorType = py::exception<std::runtime_error>(m, "CodecError", PyExc_ValueError);
  m.attr("CodecError").attr("__doc__") =
      "Malformed stream bytes (a ValueError): .status is the CodecStatus (e.g. CodecStatus.HeaderChecksum, "
      ".status.name 'HeaderChecksum'), the message names it and says what it means.";
  codecStatusType = py::enum_<CodecStatus>(m, "CodecStatus", "Why a frame was refused (probecast/codec/status.h).")
                        .value("Ok", CodecStatus::Ok)
                        .value("Truncated", CodecStatus::Truncated)
                        .value("BadMagic", CodecStatus::BadMagic)
                        .value("UnsupportedVersion", CodecStatus::UnsupportedVersion)
                        .value("BadRepresentation", CodecStatus::BadRepresentation)
                        .value("BadLayout", CodecStatus::BadLayout)
                        .value("LayoutMismatch", CodecStatus::LayoutMismatch)
                        .value("HeaderChecksum", CodecStatus::HeaderChecksum)
                        .value("SectionChecksum", CodecStatus::SectionChecksum)
                        .value("BadBrickIndex", CodecStatus::BadBrickIndex)
                        .value("DuplicateBrick", CodecStatus::DuplicateBrick)
                        .value("BadSectionKind", CodecStatus::BadSectionKind)
                        .value("SectionTooLarge", CodecStatus::SectionTooLarge)
                        .value("DecompressFailed", CodecStatus::DecompressFailed)
                        .value("SizeMismatch", CodecStatus::SizeMismatch)
                        .value("BaseVersionMismatch", CodecStatus::BaseVersionMismatch)
                        .value("BadVersion", CodecStatus::BadVersion)
                        .value("BadMask", CodecStatus::BadMask)
                        .value("BadSymbol", CodecStatus::BadSymbol)
                        .value("TrailingBytes", CodecStatus::TrailingBytes)
                        .value("NonCanonical", CodecStatus::NonCanonical);
  m.attr("PROBE_FLOATS") = kProbeFloats;
  py::list names;
  for (Representation r : kAllRepresentations) names.append(representationName(r));
  m.attr("REPRESENTATIONS") = py::tuple(names);

  m.def(
      "record_size", [](const std::string& repr) { return recordSize(reprOf(repr)); }, py::arg("repr"),
      "Bytes per probe record: l1 13, zh3h 13, zh3 16, l2 28, fp16 56.");

  m.def(
      "encode",
      [](const py::array& probes, const std::string& repr, const py::object& outArg) {
        const Representation r = reprOf(repr);
        const float* in = checkedData<float>(probes, "probes", {-1, kProbeFloats});
        const size_t n = static_cast<size_t>(probes.shape(0));
        const size_t bytes = recordSize(r);
        py::array_t<uint8_t> out =
            outputArray<uint8_t>(outArg, "out", static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(bytes));
        uint8_t* o = out.mutable_data();
        {
          py::gil_scoped_release release;
          for (size_t i = 0; i < n; ++i) encodeProbeRecord(r, in + i * kProbeFloats, o + i * bytes);
        }
        return out;
      },
      py::arg("probes"), py::arg("repr"), py::arg("out") = py::none(),
      "Encodes probes (N, 27) float32 (see the module's conventions) into records (N, record_size(repr)) uint8, "
      "as the C++ encodeProbeRecord (ratio records: DC as RGB9E5, other coefficients as ratios to the DC). "
      "out: an (N, record_size(repr)) uint8 C-contiguous array to write into (reused, no allocation).");

  m.def(
      "decode",
      [](const py::array& records, const std::string& repr, bool zh3PerPixel, const py::object& outArg) {
        const Representation r = reprOf(repr);
        const size_t bytes = recordSize(r);
        const uint8_t* in = checkedData<uint8_t>(records, "records", {-1, static_cast<py::ssize_t>(bytes)});
        const size_t n = static_cast<size_t>(records.shape(0));
        py::array_t<float> out = outputArray<float>(outArg, "out", static_cast<py::ssize_t>(n), kProbeFloats);
        float* o = out.mutable_data();
        size_t bad = n;
        {
          py::gil_scoped_release release;
          for (size_t i = 0; i < n; ++i)
            if (!decodeProbeRecord(r, in + i * bytes, o + i * kProbeFloats, zh3PerPixel) && bad == n) bad = i;
        }
        if (bad != n) throw py::value_error("records: fp16 record " + std::to_string(bad) + " holds Inf or NaN");
        return out;
      },
      py::arg("records"), py::arg("repr"), py::arg("zh3_per_pixel") = false, py::arg("out") = py::none(),
      "Decodes records (N, record_size(repr)) uint8 into probes (N, 27) float32. For zh3h, zh3_per_pixel=False "
      "gives each probe as the encoder chose it (hallucinated L2 band, or plain L1), True the form of a renderer "
      "that hallucinates per pixel (L1, and an L2 band of 0 or minus the probe's own hallucination). "
      "Raises ValueError for fp16 records holding Inf or NaN. out: an (N, 27) float32 C-contiguous array to write "
      "into (reused, no allocation).");

  m.def(
      "project_equirect",
      [](const py::array& image, float rotationY) {
        const float* rgb = checkedData<float>(image, "image", {-1, -1, 3});
        const int h = static_cast<int>(image.shape(0)), w = static_cast<int>(image.shape(1));
        if (w < 1 || h < 1) throw py::value_error("image: empty");
        py::array_t<float> out(kProbeFloats);
        float* o = out.mutable_data();
        {
          py::gil_scoped_release release;
          equirectProjectSh(rgb, w, h, o, rotationY);
        }
        return out;
      },
      py::arg("image"), py::arg("rotation_y") = 0.0f,
      "Float L2 SH (27,) float32 of an equirectangular map of linear radiance, image (H, W, 3) float32, top row +Y, "
      "u = 0 at the left, centre of the map -Z, u = 0.75 +X (as probecast bench codec). rotation_y rotates the map "
      "about +Y, radians. Summed in double over pixels weighted by their exact solid angle.");

  m.def(
      "irradiance",
      [](const py::array& probe, const py::array& normals, int bands) {
        const float* p = checkedData<float>(probe, "probe", {kProbeFloats});
        const float* nn = checkedData<float>(normals, "normals", {-1, 3});
        if (bands != 2 && bands != 3) throw py::value_error("bands must be 2 (L0..L1) or 3 (L0..L2)");
        const size_t n = static_cast<size_t>(normals.shape(0));
        py::array_t<float> out({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(3)});
        float* o = out.mutable_data();
        {
          py::gil_scoped_release release;
          for (size_t i = 0; i < n; ++i) shEvalIrradiance(p, nn[i * 3], nn[i * 3 + 1], nn[i * 3 + 2], o + i * 3, bands);
        }
        return out;
      },
      py::arg("probe"), py::arg("normals"), py::arg("bands") = 3,
      "Irradiance (M, 3) float32 of one probe (27,) float32 at unit normals (M, 3) float32: "
      "E(n) = sum_l A_l sum_m c_lm Y_lm(n), A = (pi, 2pi/3, pi/4), not divided by pi, not clamped.");

  m.def(
      "fibonacci_sphere", [](int count) {
        if (count < 1) throw py::value_error("count must be positive");
        std::vector<float> v = fibonacciSphere(count);
        py::array_t<float> out({static_cast<py::ssize_t>(count), static_cast<py::ssize_t>(3)});
        std::memcpy(out.mutable_data(), v.data(), v.size() * sizeof(float));
        return out;
      },
      py::arg("count"), "Equal-area spherical Fibonacci set of unit vectors (count, 3) float32 (the bench's normals).");

  m.def(
      "brute_force_irradiance",
      [](const py::array& image, const py::array& normals) {
        const float* rgb = checkedData<float>(image, "image", {-1, -1, 3});
        const float* nn = checkedData<float>(normals, "normals", {-1, 3});
        const int h = static_cast<int>(image.shape(0)), w = static_cast<int>(image.shape(1));
        const size_t n = static_cast<size_t>(normals.shape(0));
        py::array_t<float> out({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(3)});
        float* o = out.mutable_data();
        {
          py::gil_scoped_release release;
          equirectIrradiance(rgb, w, h, nn, n, o);
        }
        return out;
      },
      py::arg("image"), py::arg("normals"),
      "True irradiance (M, 3) float32 of an equirect map (H, W, 3) float32 at unit normals (M, 3): "
      "the integral of L(w) max(0, n.w) over the sphere (not divided by pi).");

  m.def(
      "downsample",
      [](const py::array& image, int factor) {
        const float* rgb = checkedData<float>(image, "image", {-1, -1, 3});
        if (factor < 1) throw py::value_error("factor must be >= 1");
        int ow = 0, oh = 0;
        std::vector<float> v;
        {
          py::gil_scoped_release release;
          v = equirectDownsample(rgb, static_cast<int>(image.shape(1)), static_cast<int>(image.shape(0)), factor, ow, oh);
        }
        py::array_t<float> out({static_cast<py::ssize_t>(oh), static_cast<py::ssize_t>(ow), static_cast<py::ssize_t>(3)});
        std::memcpy(out.mutable_data(), v.data(), v.size() * sizeof(float));
        return out;
      },
      py::arg("image"), py::arg("factor"),
      "Solid-angle-weighted box downsample of an equirect map by an integer factor (keeps the integral of radiance).");

  m.def(
      "irradiance_rmse_rel",
      [](const py::array& probe, const py::array& normals, const py::array& reference) {
        const float* p = checkedData<float>(probe, "probe", {kProbeFloats});
        const float* nn = checkedData<float>(normals, "normals", {-1, 3});
        const float* ref = checkedData<float>(reference, "reference", {normals.shape(0), 3});
        py::gil_scoped_release release;
        return irradianceRmseRel(p, nn, ref, static_cast<size_t>(normals.shape(0)));
      },
      py::arg("probe"), py::arg("normals"), py::arg("reference"),
      "The bench's irradiance error of one probe against reference irradiance (M, 3) at normals (M, 3): "
      "sqrt(sum |E_probe - E_ref|^2) / sqrt(sum |E_ref|^2), RGB pooled, no clamping (0 if the reference is 0).");

  m.def(
      "irradiance_rmse_rel_sh",
      [](const py::array& test, const py::array& reference) {
        const float* t = checkedData<float>(test, "test", {-1, kProbeFloats});
        const float* r = checkedData<float>(reference, "reference", {test.shape(0), kProbeFloats});
        py::gil_scoped_release release;
        double err = 0, energy = 0;
        for (py::ssize_t i = 0; i < test.shape(0); ++i)
          irradianceErrorEnergy(t + i * kProbeFloats, r + i * kProbeFloats, err, energy);
        return energy > 0 ? std::sqrt(err / energy) : 0.0;
      },
      py::arg("test"), py::arg("reference"),
      "Exact irradiance error over the whole sphere of probes (N, 27) against reference probes (N, 27), pooled "
      "over probes and RGB: sqrt(sum_l A_l^2 sum_m dc_lm^2 / sum_l A_l^2 sum_m c_lm^2) (the bench's 'vs float l2').");

#ifdef PROBECAST_PYTHON_IMAGING
  m.def(
      "load_envmap",
      [](const std::string& path) {
        std::vector<float> rgb;
        int w = 0, h = 0;
        std::string error;
        const std::string lower = [&] {
          std::string s = path;
          for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
          return s;
        }();
        const auto endsWith = [&](const char* ext) {
          const size_t n = std::strlen(ext);
          return lower.size() >= n && lower.compare(lower.size() - n, n, ext) == 0;
        };
        bool ok = false;
        if (endsWith(".hdr")) ok = imaging::readHdr(path, rgb, w, h, error);
        else if (endsWith(".exr")) ok = imaging::readExr(path, rgb, w, h, error);
        else error = path + ": not an environment map (expected .hdr or .exr)";
        if (!ok) throw py::value_error(error);
        for (float& v : rgb)
          if (!std::isfinite(v) || v < 0.0f) v = 0.0f;  // radiance is finite and non-negative, as the bench
        py::array_t<float> out({static_cast<py::ssize_t>(h), static_cast<py::ssize_t>(w), static_cast<py::ssize_t>(3)});
        std::memcpy(out.mutable_data(), rgb.data(), rgb.size() * sizeof(float));
        return out;
      },
      py::arg("path"),
      "Loads an equirect .hdr or .exr as (H, W, 3) float32 linear radiance, non-finite and negative values set to 0 "
      "(as probecast bench codec).");
#endif

  // Temporal stream.
  py::class_<PyStreamEncoder>(m, "StreamEncoder",
                              "Brick-based temporal encoder of a probe grid (probe (x, y, z) at index x + nx (y + ny z)). "
                              "Its reconstruction is bit-identical to what a StreamDecoder holds after the same frames.")
      .def(py::init<const std::array<int, 3>&, const std::string&, int, int, int, bool, float>(), py::arg("grid"),
           py::arg("repr"), py::arg("brick") = 4, py::arg("deadzone") = 0, py::arg("zstd_level") = 3,
           py::arg("compress") = true, py::arg("error_bound") = 0.0f,
           "grid = (nx, ny, nz) probes; repr l1/zh3h/zh3/l2/fp16; brick = probes per brick edge (1..8); deadzone = "
           "changes of at most this many quantisation steps are not sent; compress=False stores sections raw; "
           "error_bound > 0 (zh3 and l2 only) sends each brick in the cheapest of l1, zh3, l2 within that relative "
           "irradiance error.")
      .def_property_readonly("count", &PyStreamEncoder::count, "Probes in the grid.")
      .def(
          "update",
          [](PyStreamEncoder& self, const py::array& probes, const py::object& active) {
            const uint32_t n = self.count();
            const float* p = checkedData<float>(probes, "probes", {static_cast<py::ssize_t>(n), kProbeFloats});
            std::vector<uint8_t> scratch;
            const uint8_t* a = activeData(active, n, scratch);
            py::gil_scoped_release release;
            return self.encoder.update(p, a);
          },
          py::arg("probes"), py::arg("active") = py::none(),
          "Ingests a frame: probes (count, 27) float32 and active (count,) uint8/bool (nonzero = active; None = all). "
          "Returns the number of bricks given a new version.")
      .def(
          "keyframe_frame",
          [](PyStreamEncoder& self) {
            {
              py::gil_scoped_release release;
              self.encoder.writeKeyframeFrame(self.frame);
            }
            return py::bytes(reinterpret_cast<const char*>(self.frame.data()), self.frame.size());
          },
          "A frame of keyframes of every brick (what a new subscriber needs), as bytes.")
      .def(
          "changed_frame",
          [](PyStreamEncoder& self) {
            self.encoder.writeChangedFrame(self.frame);
            return py::bytes(reinterpret_cast<const char*>(self.frame.data()), self.frame.size());
          },
          "A frame with the delta of every brick changed by the last update() (for a subscriber holding everything).")
      .def(
          "reconstruction",
          [](const PyStreamEncoder& self) { return probesArray(self.encoder.reconstruction(), self.count()); },
          "The decoder's reconstruction (count, 27) float32 (0 for inactive probes), a copy.")
      .def(
          "active", [](const PyStreamEncoder& self) { return maskArray(self.encoder.activeMask(), self.count()); },
          "Active flags (count,) uint8, a copy.")
      .def_property_readonly("frame_sequence", [](const PyStreamEncoder& self) { return self.encoder.frameSequence(); });

  py::class_<PyStreamDecoder>(m, "StreamDecoder", "Decoder of a probecast stream of a fixed grid and representation.")
      .def(py::init<const std::array<int, 3>&, const std::string&, int, bool>(), py::arg("grid"), py::arg("repr"),
           py::arg("brick") = 4, py::arg("zh3_per_pixel") = false,
           "grid = (nx, ny, nz), repr and brick as the encoder's; zh3_per_pixel as decode().")
      .def_property_readonly("count", &PyStreamDecoder::count, "Probes in the grid.")
      .def(
          "apply",
          [](PyStreamDecoder& self, const py::bytes& frame) {
            const std::string_view bytes = frame;
            CodecStatus status;
            {
              py::gil_scoped_release release;
              status = self.decoder.apply(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
            }
            if (status != CodecStatus::Ok) {
              py::object member = codecStatusType(status);
              const std::string name = py::str(member.attr("name"));
              py::object err = codecErrorType("malformed frame: " + name + " (" + codecStatusName(status) + ")");
              err.attr("status") = member;
              PyErr_SetObject(codecErrorType.ptr(), err.ptr());
              throw py::error_already_set();
            }
          },
          py::arg("frame"),
          "Applies one frame (bytes). All or nothing: on malformed input raises CodecError (a ValueError) whose "
          ".status is the CodecStatus, and the decoder's state is unchanged.")
      .def(
          "probes", [](const PyStreamDecoder& self) { return probesArray(self.decoder.probes(), self.count()); },
          "What it holds, (count, 27) float32 (0 for inactive probes), a copy.")
      .def(
          "active", [](const PyStreamDecoder& self) { return maskArray(self.decoder.activeMask(), self.count()); },
          "Active flags (count,) uint8 (1 = active), a copy.")
      .def_property_readonly("last_frame_sequence",
                             [](const PyStreamDecoder& self) { return self.decoder.lastFrameSequence(); });

  // Probe files.
  m.def(
      "read_probe_file",
      [](const std::string& path) {
        ProbeVolume v;
        std::string error;
        bool ok;
        {
          py::gil_scoped_release release;
          ok = readProbeFile(path, v, error);
        }
        if (!ok) throw py::value_error(error);
        py::dict d;
        d["dims"] = py::make_tuple(v.grid.dims[0], v.grid.dims[1], v.grid.dims[2]);
        d["bounds_min"] = py::make_tuple(v.grid.bounds.min[0], v.grid.bounds.min[1], v.grid.bounds.min[2]);
        d["bounds_max"] = py::make_tuple(v.grid.bounds.max[0], v.grid.bounds.max[1], v.grid.bounds.max[2]);
        d["probes"] = probesArray(v.probes.data(), v.count());
        d["active"] = maskArray(v.active.data(), v.count());
        d["updates"] = v.updates;
        d["samples_per_probe"] = v.samplesPerProbe;
        if (v.scene.known()) {
          static const char* digits = "0123456789abcdef";
          std::string hex;
          for (uint8_t b : v.scene.hash) hex += {digits[b >> 4], digits[b & 15]};
          d["scene_hash"] = hex;
          d["scene_manifest"] = v.scene.manifest;
        } else {
          d["scene_hash"] = py::none();
          d["scene_manifest"] = py::none();
        }
        d["scene_time"] = v.scene.time;
        return d;
      },
      py::arg("path"),
      "Reads a probe volume file (probecast bake): dict with dims (nx, ny, nz), bounds_min/bounds_max (metres, "
      "positions of the first and last probe), probes (N, 27) float32, active (N,) uint8, updates, "
      "samples_per_probe, and the scene it was traced in: scene_hash (hex SHA-256 of scene_manifest, the scene "
      "package's JSON; both None when the file names no scene) and scene_time (seconds). Raises ValueError naming "
      "what failed.");

  m.def(
      "write_probe_file",
      [](const std::string& path, const std::array<uint32_t, 3>& dims, const py::array& probes, const py::object& active,
         const std::array<float, 3>& boundsMin, const std::array<float, 3>& boundsMax, uint32_t updates,
         uint32_t samplesPerProbe) {
        ProbeVolume v;
        for (int k = 0; k < 3; ++k) {
          v.grid.dims[k] = dims[k];
          v.grid.bounds.min[k] = boundsMin[k];
          v.grid.bounds.max[k] = boundsMax[k];
        }
        const uint64_t n = static_cast<uint64_t>(dims[0]) * dims[1] * dims[2];
        if (n == 0 || n > kMaxProbes) throw py::value_error("dims: 1 to 2^24 probes");
        const float* p = checkedData<float>(probes, "probes", {static_cast<py::ssize_t>(n), kProbeFloats});
        std::vector<uint8_t> scratch;
        const uint8_t* a = activeData(active, static_cast<uint32_t>(n), scratch);
        v.probes.assign(p, p + n * kProbeFloats);
        v.active.assign(n, 1);
        if (a) v.active.assign(a, a + n);
        v.updates = updates;
        v.samplesPerProbe = samplesPerProbe;
        std::string error;
        if (!checkProbeVolume(v, error) || !writeProbeFile(path, v, error)) throw py::value_error(error);
      },
      py::arg("path"), py::arg("dims"), py::arg("probes"), py::arg("active") = py::none(),
      py::arg("bounds_min") = std::array<float, 3>{-1, -1, -1}, py::arg("bounds_max") = std::array<float, 3>{1, 1, 1},
      py::arg("updates") = 0, py::arg("samples_per_probe") = 0,
      "Writes a probe volume file: dims (nx, ny, nz), probes (N, 27) float32, active (N,) uint8/bool (None = all "
      "active, values 0/1), bounds in metres. Raises ValueError for an invalid volume or an I/O error.");
}
