// Internal to the laz library's LAZ decoder (laz.h): the item types, the field decoders both
// compressors share (the x/y medians, GPS time, RGB) and the two chunk decoders: laz_pointwise.cpp
// (compressor 2, point formats 0-3) and laz_layered.cpp (compressor 3, formats 6-8). GPS time
// bits and coordinates are unsigned where the format wraps, so no input overflows a signed value.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "laz_coder.h"
#include "lodrefine/laz/laz.h"

namespace lodrefine::laz {

// Item types of the LASzip VLR.
enum ItemType : std::uint16_t {
  kByte = 0,
  kPoint10 = 6,
  kGpsTime11 = 7,
  kRgb12 = 8,
  kWavePacket13 = 9,
  kPoint14 = 10,
  kRgb14 = 11,
  kRgbNir14 = 12,
  kWavePacket14 = 13,
  kByte14 = 14
};

// Median of the last five values, kept sorted with LASzip's insertion rule.
class Median5 {
 public:
  std::int32_t get() const { return v_[2]; }
  void add(std::int32_t x) {
    if (high_) {
      if (x < v_[2]) {
        v_[4] = v_[3], v_[3] = v_[2];
        if (x < v_[0]) v_[2] = v_[1], v_[1] = v_[0], v_[0] = x;
        else if (x < v_[1]) v_[2] = v_[1], v_[1] = x;
        else v_[2] = x;
      } else {
        if (x < v_[3]) v_[4] = v_[3], v_[3] = x;
        else v_[4] = x;
        high_ = false;
      }
    } else {
      if (v_[2] < x) {
        v_[0] = v_[1], v_[1] = v_[2];
        if (v_[4] < x) v_[2] = v_[3], v_[3] = v_[4], v_[4] = x;
        else if (v_[3] < x) v_[2] = v_[3], v_[3] = x;
        else v_[2] = x;
      } else {
        if (v_[1] < x) v_[0] = v_[1], v_[1] = x;
        else v_[0] = x;
        high_ = true;
      }
    }
  }

 private:
  std::array<std::int32_t, 5> v_{};
  bool high_ = true;
};

// GPSTIME11 v2 and the GPS time of POINT14 v3: the double's bits as an integer, predicted
// from up to four interleaved time sequences by a multiple of their last difference. v3 codes
// "unchanged" outside (a flag of the point), so its codes from "unchanged" on are one lower.
// One state, decoded from (next) or encoded into (encode): the encoder picks the code LASzip's
// writer does, the decoder follows any code.
class GpsTimeCoder {
 public:
  explicit GpsTimeCoder(bool v3 = false)
      : v3_(v3), multi_(v3 ? kMultiTotal - 1 : kMultiTotal), zero_diff_(v3 ? 5 : 6) {}
  void next(ArithmeticDecoder& dec, unsigned char* out) {
    // A switch to another sequence is followed by that sequence's own code. An encoder switches
    // once, to a sequence the time fits; a corrupt stream could switch on without end, consuming
    // no bytes.
    int switches = 0;
    while (!decode_one(dec))
      if (++switches > kMaxSwitches) throw Corrupt{"GPS time switches sequence without end"};
    for (int i = 0; i < 8; ++i) out[i] = (unsigned char)(time_[last_] >> (8 * i));
  }
  std::uint64_t last() const { return time_[last_]; }
  void seed(std::uint64_t t) { time_[0] = t; }
  // Codes the time bits `t` (v3: only a changed time, the point flags "unchanged").
  void encode(ArithmeticEncoder& enc, std::uint64_t t) {
    while (!encode_one(enc, t)) {
    }
  }

 private:
  static constexpr int kMaxSwitches = 3;  // a switch to each other sequence
  static constexpr int kMulti = 500, kMultiMinus = -10, kMultiUnchanged = kMulti - kMultiMinus + 1,
                       kMultiCodeFull = kMulti - kMultiMinus + 2, kMultiTotal = kMulti - kMultiMinus + 6;

  // Decodes one code; false when it only switched to another sequence.
  bool decode_one(ArithmeticDecoder& dec) {
    if (diff_[last_] == 0) {
      const std::uint32_t multi = dec.symbol(zero_diff_) + (v3_ ? 1 : 0);
      if (multi == 1) {
        diff_[last_] = ic_.decode(dec, 0, 0);
        time_[last_] += std::uint64_t(std::int64_t(diff_[last_]));
        extreme_[last_] = 0;
      } else if (multi == 2) {
        start_full_sequence(dec);
      } else if (multi > 2) {
        last_ = (last_ + multi - 2) & 3;
        return false;
      }
      return true;
    }
    int multi = int(dec.symbol(multi_));
    if (v3_ && multi >= kMultiUnchanged) ++multi;
    if (multi == 1) {
      time_[last_] += std::uint64_t(std::int64_t(ic_.decode(dec, diff_[last_], 1)));
      extreme_[last_] = 0;
    } else if (multi < kMultiUnchanged) {
      std::int32_t diff;
      if (multi == 0) {
        diff = ic_.decode(dec, 0, 7);
        count_extreme(diff);
      } else if (multi < kMulti) {
        diff = ic_.decode(dec, times(multi, diff_[last_]), multi < 10 ? 2 : 3);
      } else if (multi == kMulti) {
        diff = ic_.decode(dec, times(kMulti, diff_[last_]), 4);
        count_extreme(diff);
      } else {
        const int minus = kMulti - multi;
        if (minus > kMultiMinus) {
          diff = ic_.decode(dec, times(minus, diff_[last_]), 5);
        } else {
          diff = ic_.decode(dec, times(kMultiMinus, diff_[last_]), 6);
          count_extreme(diff);
        }
      }
      time_[last_] += std::uint64_t(std::int64_t(diff));
    } else if (multi == kMultiCodeFull) {
      start_full_sequence(dec);
    } else if (multi > kMultiCodeFull) {
      last_ = (last_ + std::uint32_t(multi - kMultiCodeFull)) & 3;
      return false;
    }
    return true;
  }
  // Encodes one code; false when it only switched to the sequence `t` continues.
  bool encode_one(ArithmeticEncoder& enc, std::uint64_t t) {
    const std::int64_t d64 = std::int64_t(t - time_[last_]);
    const bool fits = d64 == std::int64_t(std::int32_t(d64));
    if (!v3_ && t == time_[last_]) {
      code(enc, diff_[last_] == 0 ? 0 : kMultiUnchanged);
    } else if (fits && diff_[last_] == 0) {
      code(enc, 1);
      ic_.encode(enc, 0, std::int32_t(d64), 0);
      diff_[last_] = std::int32_t(d64);
      extreme_[last_] = 0;
    } else if (fits) {
      encode_multiple(enc, std::int32_t(d64));
    } else {
      for (std::uint32_t i = 1; i < 4; ++i) {
        const std::int64_t other = std::int64_t(t - time_[(last_ + i) & 3]);
        if (other != std::int64_t(std::int32_t(other))) continue;
        code(enc, (diff_[last_] == 0 ? 2 : kMultiCodeFull) + int(i));
        last_ = (last_ + i) & 3;
        return false;
      }
      code(enc, diff_[last_] == 0 ? 2 : kMultiCodeFull);
      next_ = (next_ + 1) & 3;
      ic_.encode(enc, std::int32_t(std::uint32_t(time_[last_] >> 32)), std::int32_t(std::uint32_t(t >> 32)), 8);
      enc.u32(std::uint32_t(t));
      last_ = next_;
      diff_[last_] = 0;
      extreme_[last_] = 0;
    }
    time_[last_] = t;
    return true;
  }
  // A difference after a non-zero one: coded as a multiple of it (LASzip's rounding in float).
  void encode_multiple(ArithmeticEncoder& enc, std::int32_t diff) {
    const std::int32_t last = diff_[last_];
    const float ratio = float(diff) / float(last);
    const int multi = ratio >= float(kMulti)        ? kMulti
                      : ratio <= float(kMultiMinus) ? kMultiMinus
                                                    : int(ratio >= 0 ? ratio + 0.5f : ratio - 0.5f);
    if (multi == 1) {
      code(enc, 1);
      ic_.encode(enc, last, diff, 1);
      extreme_[last_] = 0;
    } else if (multi > 0 && multi < kMulti) {
      code(enc, multi);
      ic_.encode(enc, times(multi, last), diff, multi < 10 ? 2 : 3);
    } else if (multi == kMulti) {
      code(enc, kMulti);
      ic_.encode(enc, times(kMulti, last), diff, 4);
      count_extreme(diff);
    } else if (multi < 0 && multi > kMultiMinus) {
      code(enc, kMulti - multi);
      ic_.encode(enc, times(multi, last), diff, 5);
    } else if (multi < 0) {
      code(enc, kMulti - kMultiMinus);
      ic_.encode(enc, times(kMultiMinus, last), diff, 6);
      count_extreme(diff);
    } else {
      code(enc, 0);
      ic_.encode(enc, 0, diff, 7);
      count_extreme(diff);
    }
  }
  // A code in v2 numbering, into the model decode_one reads it from.
  void code(ArithmeticEncoder& enc, int c) {
    if (diff_[last_] == 0) enc.symbol(zero_diff_, std::uint32_t(c - (v3_ ? 1 : 0)));
    else enc.symbol(multi_, std::uint32_t(v3_ && c > kMultiUnchanged ? c - 1 : c));
  }
  static std::int32_t times(int a, std::int32_t b) { return std::int32_t(std::uint32_t(a) * std::uint32_t(b)); }
  void count_extreme(std::int32_t diff) {
    if (++extreme_[last_] > 3) diff_[last_] = diff, extreme_[last_] = 0;
  }
  void start_full_sequence(ArithmeticDecoder& dec) {
    next_ = (next_ + 1) & 3;
    const std::int32_t high = ic_.decode(dec, std::int32_t(std::uint32_t(time_[last_] >> 32)), 8);
    time_[next_] = std::uint64_t(std::uint32_t(high)) << 32 | dec.u32();
    last_ = next_;
    diff_[last_] = 0;
    extreme_[last_] = 0;
  }

  bool v3_;
  std::array<std::uint64_t, 4> time_{};
  std::array<std::int32_t, 4> diff_{}, extreme_{};
  std::uint32_t last_ = 0, next_ = 0;
  SymbolModel multi_, zero_diff_;
  IntegerCoder ic_{32, 9};
};

// The colour models of RGB12 v2 and RGB14 v3 (one set per scanner channel there).
struct RgbModels {
  SymbolModel byte_used{128};
  std::array<SymbolModel, 6> diff{SymbolModel(256), SymbolModel(256), SymbolModel(256),
                                  SymbolModel(256), SymbolModel(256), SymbolModel(256)};
};

// One colour: which bytes changed (bit 6: green and blue differ from red), then each changed
// byte as a correction of a prediction from red's change.
inline std::array<std::uint32_t, 3> decode_rgb(ArithmeticDecoder& dec, RgbModels& m,
                                               const std::array<std::uint32_t, 3>& last) {
  const std::uint32_t sym = dec.symbol(m.byte_used);
  std::array<std::uint32_t, 3> c{};
  const auto clamp8 = [](int v) { return std::uint32_t(std::clamp(v, 0, 255)); };
  const auto low = [](std::uint32_t v) { return int(v & 0xff); };
  const auto high = [](std::uint32_t v) { return int(v >> 8); };
  c[0] = sym & 1 ? (dec.symbol(m.diff[0]) + last[0]) & 0xff : last[0] & 0xff;
  c[0] |= sym & 2 ? ((dec.symbol(m.diff[1]) + (last[0] >> 8)) & 0xff) << 8 : last[0] & 0xff00;
  if (!(sym & 64)) return {c[0], c[0], c[0]};
  int diff = low(c[0]) - low(last[0]);
  c[1] = sym & 4 ? (dec.symbol(m.diff[2]) + clamp8(diff + low(last[1]))) & 0xff : last[1] & 0xff;
  if (sym & 16) {
    const std::uint32_t corr = dec.symbol(m.diff[4]);
    diff = (diff + low(c[1]) - low(last[1])) / 2;
    c[2] = (corr + clamp8(diff + low(last[2]))) & 0xff;
  } else {
    c[2] = last[2] & 0xff;
  }
  diff = high(c[0]) - high(last[0]);
  c[1] |= sym & 8 ? ((dec.symbol(m.diff[3]) + clamp8(diff + high(last[1]))) & 0xff) << 8 : last[1] & 0xff00;
  if (sym & 32) {
    const std::uint32_t corr = dec.symbol(m.diff[5]);
    diff = (diff + high(c[1]) - high(last[1])) / 2;
    c[2] |= ((corr + clamp8(diff + high(last[2]))) & 0xff) << 8;
  } else {
    c[2] |= last[2] & 0xff00;
  }
  return c;
}

// The inverse of decode_rgb: returns the byte-change mask it coded (0: the colour equals `last`).
inline std::uint32_t encode_rgb(ArithmeticEncoder& enc, RgbModels& m, const std::array<std::uint32_t, 3>& last,
                                const std::array<std::uint32_t, 3>& c) {
  const auto low = [](std::uint32_t v) { return int(v & 0xff); };
  const auto high = [](std::uint32_t v) { return int(v >> 8); };
  std::uint32_t sym = 0;
  for (int i = 0; i < 3; ++i)
    sym |= std::uint32_t(low(c[i]) != low(last[i])) << (2 * i) | std::uint32_t(high(c[i]) != high(last[i]))
                                                                     << (2 * i + 1);
  const bool colour = c[0] != c[1] || c[0] != c[2];
  enc.symbol(m.byte_used, sym | std::uint32_t(colour) << 6);
  const auto clamp8 = [](int v) { return std::clamp(v, 0, 255); };
  const auto fold = [](int v) { return std::uint32_t(v) & 0xff; };
  int diff_l = 0, diff_h = 0;
  if (sym & 1) diff_l = low(c[0]) - low(last[0]), enc.symbol(m.diff[0], fold(diff_l));
  if (sym & 2) diff_h = high(c[0]) - high(last[0]), enc.symbol(m.diff[1], fold(diff_h));
  if (!colour) return sym;
  if (sym & 4) enc.symbol(m.diff[2], fold(low(c[1]) - clamp8(diff_l + low(last[1]))));
  if (sym & 16) {
    diff_l = (diff_l + low(c[1]) - low(last[1])) / 2;
    enc.symbol(m.diff[4], fold(low(c[2]) - clamp8(diff_l + low(last[2]))));
  }
  if (sym & 8) enc.symbol(m.diff[3], fold(high(c[1]) - clamp8(diff_h + high(last[1]))));
  if (sym & 32) {
    diff_h = (diff_h + high(c[1]) - high(last[1])) / 2;
    enc.symbol(m.diff[5], fold(high(c[2]) - clamp8(diff_h + high(last[2]))));
  }
  return sym;
}

// WAVEPACKET13 v1 and the WAVEPACKET14 v3 layer (29 bytes: descriptor index, the 64-bit byte
// offset, packet size, return point and x/y/z as float bits): the index, then how the offset
// follows the last (same, right after the last packet, a 32-bit difference, raw), then each
// 32-bit field predicted by the last one's. One set per scanner channel in v3.
struct WavePacketModels {
  SymbolModel packet_index{256};
  std::array<SymbolModel, 4> offset_diff{SymbolModel(4), SymbolModel(4), SymbolModel(4), SymbolModel(4)};
  IntegerCoder ic_offset_diff{32}, ic_packet_size{32}, ic_return_point{32}, ic_xyz{32, 3};
  std::int32_t last_diff = 0;
  std::uint32_t last_sym = 0;
};
constexpr std::size_t kWavePacketSize = 29;

inline void decode_wavepacket(ArithmeticDecoder& dec, WavePacketModels& m, const unsigned char* last,
                              unsigned char* out) {
  out[0] = (unsigned char)dec.symbol(m.packet_index);
  const std::uint64_t last_offset = get_u64(last + 1);
  m.last_sym = dec.symbol(m.offset_diff[m.last_sym]);
  std::uint64_t offset = last_offset;
  if (m.last_sym == 1) {
    offset += get_u32(last + 9);
  } else if (m.last_sym == 2) {
    m.last_diff = m.ic_offset_diff.decode(dec, m.last_diff, 0);
    offset += std::uint64_t(std::int64_t(m.last_diff));
  } else if (m.last_sym == 3) {
    const std::uint64_t low = dec.u32();
    offset = std::uint64_t(dec.u32()) << 32 | low;
  }
  for (int i = 0; i < 8; ++i) out[1 + i] = (unsigned char)(offset >> (8 * i));
  put_u32(out + 9, std::uint32_t(m.ic_packet_size.decode(dec, std::int32_t(get_u32(last + 9)), 0)));
  put_u32(out + 13, std::uint32_t(m.ic_return_point.decode(dec, std::int32_t(get_u32(last + 13)), 0)));
  for (std::uint32_t k = 0; k < 3; ++k)
    put_u32(out + 17 + 4 * k, std::uint32_t(m.ic_xyz.decode(dec, std::int32_t(get_u32(last + 17 + 4 * k)), k)));
}

inline void encode_wavepacket(ArithmeticEncoder& enc, WavePacketModels& m, const unsigned char* last,
                              const unsigned char* item) {
  enc.symbol(m.packet_index, item[0]);
  const std::uint64_t offset = get_u64(item + 1), last_offset = get_u64(last + 1);
  const auto diff = std::int64_t(offset - last_offset);
  const std::uint32_t sym = offset == last_offset                       ? 0
                            : offset == last_offset + get_u32(last + 9) ? 1
                            : diff == std::int64_t(std::int32_t(diff))  ? 2
                                                                        : 3;
  enc.symbol(m.offset_diff[m.last_sym], sym);
  m.last_sym = sym;
  if (sym == 2) {
    m.ic_offset_diff.encode(enc, m.last_diff, std::int32_t(diff), 0);
    m.last_diff = std::int32_t(diff);
  } else if (sym == 3) {
    enc.u32(std::uint32_t(offset));
    enc.u32(std::uint32_t(offset >> 32));
  }
  const auto field = [](const unsigned char* p, std::size_t at) { return std::int32_t(get_u32(p + at)); };
  m.ic_packet_size.encode(enc, field(last, 9), field(item, 9), 0);
  m.ic_return_point.encode(enc, field(last, 13), field(item, 13), 0);
  for (std::uint32_t k = 0; k < 3; ++k) m.ic_xyz.encode(enc, field(last, 17 + 4 * k), field(item, 17 + 4 * k), k);
}

inline std::array<std::uint32_t, 3> get_rgb(const unsigned char* p) {
  return {get_u16(p), get_u16(p + 2), get_u16(p + 4)};
}
inline void put_rgb(unsigned char* p, const std::array<std::uint32_t, 3>& c) {
  for (int i = 0; i < 3; ++i) put_u16(p + 2 * i, std::uint16_t(c[i]));
}

// The chunk decoders: decode the first `n` points of one chunk (its compressed bytes in `in`,
// its items checked by read_layout) into `record` one at a time, call on_record after each and
// count it in `done`. Throw OutOfData when the chunk's bytes end first.
using RecordSink = std::function<void(const unsigned char*)>;
void decode_pointwise_chunk(const std::vector<Item>& items, ByteReader& in, std::uint64_t n, unsigned char* record,
                            std::uint64_t& done, const RecordSink& on_record);
void decode_layered_chunk(const std::vector<Item>& items, ByteReader& in, std::uint64_t n, unsigned char* record,
                          std::uint64_t& done, const RecordSink& on_record);

// One chunk's encoder: its records in, its compressed bytes out (the first record raw, as the
// decoders read it). The encoders mirror the decoders' states, so every record round-trips.
class ChunkEncoder {
 public:
  virtual ~ChunkEncoder() = default;
  virtual void add(const unsigned char* record) = 0;
  virtual std::vector<unsigned char> finish() = 0;  // after the last add; at least one record
};
std::unique_ptr<ChunkEncoder> pointwise_chunk_encoder(const std::vector<Item>& items, std::size_t record_length);
std::unique_ptr<ChunkEncoder> layered_chunk_encoder(const std::vector<Item>& items, std::size_t record_length);

// Their shared loop, over a chunk class with a constructor (items, in) and decode(record).
template <class Chunk>
void decode_points(const std::vector<Item>& items, ByteReader& in, std::uint64_t n, unsigned char* record,
                   std::uint64_t& done, const RecordSink& on_record) {
  Chunk chunk(items, in);
  for (std::uint64_t k = 0; k < n; ++k, ++done) {
    chunk.decode(record);
    on_record(record);
  }
}

}  // namespace lodrefine::laz
