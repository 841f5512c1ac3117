// Shared by the client fuzz target and its seed writer: the input is what a server sends a
// viewer, as records of [u8 kind][u16 length, little-endian][bytes]: kind 0 a ServerMessage
// (Subscribe), kind 1 a SceneChunk (GetScene). See client_fuzz.cpp.
#pragma once

#include <cstdint>
#include <string>

namespace probecast::fuzz {

enum ClientRecord : uint8_t { kServerMessage = 0, kSceneChunk = 1 };

inline void appendRecord(std::string& out, ClientRecord kind, const std::string& bytes) {
  const size_t n = bytes.size() < 0xffff ? bytes.size() : 0xffff;
  out.push_back(static_cast<char>(kind));
  out.push_back(static_cast<char>(n & 0xff));
  out.push_back(static_cast<char>(n >> 8));
  out.append(bytes, 0, n);
}

}  // namespace probecast::fuzz
