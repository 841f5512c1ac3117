// Error codes for untrusted input (bytes off the network, files). Programming mistakes assert.
#pragma once

namespace probecast {

enum class CodecStatus : int {
  Ok = 0,
  Truncated,            // fewer bytes than a header or section announces
  BadMagic,             // not a probecast frame
  UnsupportedVersion,   // format version this decoder does not know
  BadRepresentation,    // unknown representation byte
  BadLayout,            // grid or brick size out of range
  LayoutMismatch,       // frame describes another grid/representation than the decoder's
  HeaderChecksum,       // header CRC does not match
  SectionChecksum,      // section CRC does not match
  BadBrickIndex,        // brick index outside the grid
  DuplicateBrick,       // the same brick twice in one frame
  BadSectionKind,       // unknown section kind or compression
  SectionTooLarge,      // declared size larger than any valid section of this layout
  DecompressFailed,     // zstd rejected the payload
  SizeMismatch,         // payload size disagrees with its masks or declared size
  BaseVersionMismatch,  // delta against a version the decoder does not hold
  BadVersion,           // version does not advance
  BadMask,              // changed probe that is not active, or stray bits past the brick
  BadSymbol,            // a decoded value outside its domain (DC code, NaN half)
  TrailingBytes,        // bytes after the last section
  NonCanonical,         // a number or payload form not in the one encoding the format allows
};

const char* codecStatusName(CodecStatus status);

}  // namespace probecast
