// LAZ decoder: LASzip's arithmetic decoder, adaptive models, integer decompressor and the
// version-2 item decoders of point formats 0–3, after the published LASzip format. All state
// is unsigned where the format wraps (coordinates, GPS time bits, corrector sums), so no
// signed overflow or negative shift happens on any input.
#include "laz.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <memory>
#include <limits>
#include <optional>

#include "text.h"

namespace lodrefine::laz {
namespace {

using io_text::fail;
using io_text::read_at;

// Item types of the LASzip VLR.
enum ItemType : std::uint16_t {
  kByte = 0, kPoint10 = 6, kGpsTime11 = 7, kRgb12 = 8, kWavePacket13 = 9,
  kPoint14 = 10, kRgb14 = 11, kRgbNir14 = 12, kWavePacket14 = 13, kByte14 = 14
};

// The decoder ran past the bytes its chunk (or table) holds: the data is truncated or corrupt.
struct OutOfData {};

// Bytes of one chunk (or the chunk table) in memory, read front to back.
class ByteReader {
 public:
  ByteReader(const unsigned char* begin, const unsigned char* end) : p_(begin), end_(end) {}
  unsigned char byte() {
    if (p_ == end_) throw OutOfData{};
    return *p_++;
  }
  void bytes(unsigned char* dst, std::size_t n) { std::memcpy(dst, take(n), n); }
  // The next n bytes, skipped.
  const unsigned char* take(std::size_t n) {
    if (std::size_t(end_ - p_) < n) throw OutOfData{};
    const unsigned char* at = p_;
    p_ += n;
    return at;
  }

 private:
  const unsigned char* p_;
  const unsigned char* end_;
};

constexpr std::uint32_t kMinLength = 0x01000000u;   // renormalise below this interval length
constexpr std::uint32_t kBitLengthShift = 13;       // bit models: probabilities of 13 bits
constexpr std::uint32_t kBitMaxCount = 1u << 13;
constexpr std::uint32_t kSymbolLengthShift = 15;    // symbol models: distributions of 15 bits
constexpr std::uint32_t kSymbolMaxCount = 1u << 15;

// Adaptive model of one binary decision.
struct BitModel {
  std::uint32_t update_cycle = 4, until_update = 4;
  std::uint32_t bit_0_prob = 1u << (kBitLengthShift - 1), bit_0_count = 1, bit_count = 2;

  void update() {
    if ((bit_count += update_cycle) > kBitMaxCount) {
      bit_count = (bit_count + 1) >> 1;
      bit_0_count = (bit_0_count + 1) >> 1;
      if (bit_0_count == bit_count) ++bit_count;
    }
    const std::uint32_t scale = 0x80000000u / bit_count;
    bit_0_prob = (bit_0_count * scale) >> (31 - kBitLengthShift);
    update_cycle = std::min<std::uint32_t>((5 * update_cycle) >> 2, 64);
    until_update = update_cycle;
  }
};

// Adaptive model of a symbol in [0, symbols): counts, rescaled into a cumulative distribution
// every update_cycle symbols (the cycle grows to (symbols + 6) * 8).
struct SymbolModel {
  explicit SymbolModel(std::uint32_t n) : symbols(n), distribution(n), count(n, 1) {
    update_cycle = n;
    update();
    until_update = update_cycle = (n + 6) >> 1;
  }
  void update() {
    if ((total_count += update_cycle) > kSymbolMaxCount) {
      total_count = 0;
      for (auto& c : count) total_count += (c = (c + 1) >> 1);
    }
    const std::uint32_t scale = 0x80000000u / total_count;
    std::uint32_t sum = 0;
    for (std::uint32_t k = 0; k < symbols; ++k) {
      distribution[k] = (scale * sum) >> (31 - kSymbolLengthShift);
      sum += count[k];
    }
    update_cycle = std::min((5 * update_cycle) >> 2, (symbols + 6) << 3);
    until_update = update_cycle;
  }

  std::uint32_t symbols;
  std::vector<std::uint32_t> distribution, count;
  std::uint32_t total_count = 0, update_cycle = 0, until_update = 0;
};

// LASzip's arithmetic decoder (Amir Said's FastAC with 32-bit interval).
class ArithmeticDecoder {
 public:
  explicit ArithmeticDecoder(ByteReader& in) : in_(in) {}
  void init() {
    value_ = 0;
    for (int i = 0; i < 4; ++i) value_ = (value_ << 8) | in_.byte();
    length_ = 0xffffffffu;
  }
  std::uint32_t bit(BitModel& m) {
    const std::uint32_t x = m.bit_0_prob * (length_ >> kBitLengthShift);
    const std::uint32_t sym = value_ >= x;
    if (sym == 0) {
      length_ = x;
      ++m.bit_0_count;
    } else {
      value_ -= x;
      length_ -= x;
    }
    if (length_ < kMinLength) renormalise();
    if (--m.until_update == 0) m.update();
    return sym;
  }
  // Bisection over the cumulative distribution: the symbol whose interval holds value_.
  std::uint32_t symbol(SymbolModel& m) {
    std::uint32_t sym = 0, x = 0, y = length_, n = m.symbols;
    length_ >>= kSymbolLengthShift;
    std::uint32_t k = n >> 1;
    do {
      const std::uint32_t z = length_ * m.distribution[k];
      if (z > value_) n = k, y = z;
      else sym = k, x = z;
    } while ((k = (sym + n) >> 1) != sym);
    value_ -= x;
    length_ = y - x;
    if (length_ < kMinLength) renormalise();
    ++m.count[sym];
    if (--m.until_update == 0) m.update();
    return sym;
  }
  // `bits` (1..32) raw bits.
  std::uint32_t bits(std::uint32_t bits) {
    if (bits > 19) {
      const std::uint32_t low = raw(16);
      return (this->bits(bits - 16) << 16) | low;
    }
    return raw(bits);
  }
  std::uint32_t u32() {
    const std::uint32_t low = raw(16);
    return (raw(16) << 16) | low;
  }

 private:
  std::uint32_t raw(std::uint32_t bits) {
    const std::uint32_t sym = value_ / (length_ >>= bits);
    value_ -= length_ * sym;
    if (length_ < kMinLength) renormalise();
    return sym;
  }
  void renormalise() {
    do value_ = (value_ << 8) | in_.byte();
    while ((length_ <<= 8) < kMinLength);
  }

  ByteReader& in_;
  std::uint32_t value_ = 0, length_ = 0xffffffffu;
};

// LASzip's integer decompressor: a value is a prediction plus a corrector whose bit length k
// is coded per context, then its bits (the high ones modelled, the rest raw). The sum wraps
// into the corrector range, as the encoder's difference did.
class IntegerDecoder {
 public:
  explicit IntegerDecoder(std::uint32_t bits = 16, std::uint32_t contexts = 1, std::uint32_t bits_high = 8)
      : bits_high_(bits_high) {
    if (bits > 0 && bits < 32) {
      corr_bits_ = bits;
      corr_range_ = 1u << bits;
      corr_min_ = -std::int32_t(corr_range_ / 2);
    } else {
      corr_bits_ = 32;
      corr_range_ = 0;
      corr_min_ = std::numeric_limits<std::int32_t>::min();
    }
    for (std::uint32_t i = 0; i < contexts; ++i) k_models_.emplace_back(corr_bits_ + 1);
    corrector_.resize(corr_bits_);
  }
  std::int32_t decode(ArithmeticDecoder& dec, std::int32_t pred, std::uint32_t context) {
    std::uint32_t real = std::uint32_t(pred) + std::uint32_t(corrector(dec, k_models_[context]));
    if (std::int32_t(real) < 0) real += corr_range_;
    else if (real >= corr_range_) real -= corr_range_;
    return std::int32_t(real);
  }
  std::uint32_t k() const { return k_; }

 private:
  std::int32_t corrector(ArithmeticDecoder& dec, SymbolModel& k_model) {
    k_ = dec.symbol(k_model);
    if (k_ == 0) return std::int32_t(dec.bit(corrector0_));  // 0 or 1
    if (k_ >= 32) return corr_min_;
    // The corrector model of each bit length is made on first use (LASzip makes all at once;
    // an unused model's state never matters).
    std::unique_ptr<SymbolModel>& model = corrector_[k_ - 1];
    if (!model) model = std::make_unique<SymbolModel>(1u << std::min(k_, bits_high_));
    std::uint32_t c = dec.symbol(*model);
    if (k_ > bits_high_) {
      const std::uint32_t low_bits = k_ - bits_high_;
      c = (c << low_bits) | dec.bits(low_bits);
    }
    // c in [2^(k-1), 2^k) stands for c + 1; c in [0, 2^(k-1)) for c - (2^k - 1).
    return std::int32_t(c >= (1u << (k_ - 1)) ? c + 1 : c - ((1u << k_) - 1));
  }

  std::uint32_t bits_high_, corr_bits_ = 32, corr_range_ = 0;
  std::int32_t corr_min_ = 0;
  std::uint32_t k_ = 0;
  std::vector<SymbolModel> k_models_;
  BitModel corrector0_;
  std::vector<std::unique_ptr<SymbolModel>> corrector_;
};

std::uint16_t get_u16(const unsigned char* p) { return io_text::get_le<std::uint16_t>(p); }
std::uint32_t get_u32(const unsigned char* p) { return io_text::get_le<std::uint32_t>(p); }
std::uint64_t get_u64(const unsigned char* p) { return io_text::get_le<std::uint64_t>(p); }
void put_u32(unsigned char* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = (unsigned char)(v >> (8 * i));
}
void put_u16(unsigned char* p, std::uint16_t v) { p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8); }

// Symbol models created on first use (LASzip keeps 256 per context byte; most stay unused).
class LazyModels {
 public:
  explicit LazyModels(std::size_t n, std::uint32_t symbols) : models_(n), symbols_(symbols) {}
  SymbolModel& operator[](std::size_t i) {
    if (!models_[i]) models_[i] = std::make_unique<SymbolModel>(symbols_);
    return *models_[i];
  }

 private:
  std::vector<std::unique_ptr<SymbolModel>> models_;
  std::uint32_t symbols_;
};

// Context tables of POINT10 v2 by (number of returns, return number): 16 contexts for the
// intensity and x/y medians, 8 levels for the z prediction. Files that number returns from 0
// or swap the two fields still get distinct contexts.
constexpr unsigned char kReturnMap[8][8] = {
    {15, 14, 13, 12, 11, 10, 9, 8}, {14, 0, 1, 3, 6, 10, 10, 9},    {13, 1, 2, 4, 7, 11, 11, 10},
    {12, 3, 4, 5, 8, 12, 12, 11},   {11, 6, 7, 8, 9, 13, 13, 12},   {10, 10, 11, 12, 13, 14, 14, 13},
    {9, 10, 11, 12, 13, 14, 15, 14}, {8, 9, 10, 11, 12, 13, 14, 15}};
constexpr unsigned char kReturnLevel[8][8] = {
    {0, 1, 2, 3, 4, 5, 6, 7}, {1, 0, 1, 2, 3, 4, 5, 6}, {2, 1, 0, 1, 2, 3, 4, 5}, {3, 2, 1, 0, 1, 2, 3, 4},
    {4, 3, 2, 1, 0, 1, 2, 3}, {5, 4, 3, 2, 1, 0, 1, 2}, {6, 5, 4, 3, 2, 1, 0, 1}, {7, 6, 5, 4, 3, 2, 1, 0}};

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

// POINT10 v2: the 20 bytes of formats 0–5 (x, y, z, intensity, return bits, class, scan
// angle, user data, point source).
class Point10Decoder {
 public:
  void first(ByteReader& in, unsigned char* out) {
    in.bytes(out, 20);
    std::memcpy(last_, out, 20);
    last_intensity_value_ = 0;  // the first point's intensity does not seed the model
  }
  void next(ArithmeticDecoder& dec, unsigned char* out) {
    const std::uint32_t changed = dec.symbol(changed_values_);
    if (changed & 32) last_[14] = (unsigned char)dec.symbol(bit_byte_[last_[14]]);
    const unsigned r = last_[14] & 7, n = (last_[14] >> 3) & 7;
    const unsigned m = kReturnMap[n][r], l = kReturnLevel[n][r];
    if (changed) {
      if (changed & 16) {
        last_intensity_value_ = std::uint16_t(ic_intensity_.decode(dec, last_intensity_[m], m < 3 ? m : 3));
        last_intensity_[m] = last_intensity_value_;
      } else {
        last_intensity_value_ = last_intensity_[m];
      }
      if (changed & 8) last_[15] = (unsigned char)dec.symbol(classification_[last_[15]]);
      if (changed & 4) last_[16] = (unsigned char)(dec.symbol(scan_angle_[(last_[14] >> 6) & 1]) + last_[16]);
      if (changed & 2) last_[17] = (unsigned char)dec.symbol(user_data_[last_[17]]);
      if (changed & 1) put_u16(last_ + 18, std::uint16_t(ic_point_source_.decode(dec, get_u16(last_ + 18), 0)));
    }
    const std::uint32_t single = n == 1;
    const std::int32_t dx = ic_dx_.decode(dec, x_median_[m].get(), single);
    put_u32(last_, get_u32(last_) + std::uint32_t(dx));
    x_median_[m].add(dx);
    const std::uint32_t kx = ic_dx_.k();
    const std::int32_t dy = ic_dy_.decode(dec, y_median_[m].get(), single + (kx < 20 ? kx & ~1u : 20));
    put_u32(last_ + 4, get_u32(last_ + 4) + std::uint32_t(dy));
    y_median_[m].add(dy);
    const std::uint32_t kz = (ic_dx_.k() + ic_dy_.k()) / 2;
    last_height_[l] = ic_z_.decode(dec, last_height_[l], single + (kz < 18 ? kz & ~1u : 18));
    put_u32(last_ + 8, std::uint32_t(last_height_[l]));
    std::memcpy(out, last_, 20);
    put_u16(out + 12, last_intensity_value_);
  }

 private:
  unsigned char last_[20] = {};
  std::uint16_t last_intensity_value_ = 0;
  std::array<std::uint16_t, 16> last_intensity_{};
  std::array<Median5, 16> x_median_, y_median_;
  std::array<std::int32_t, 8> last_height_{};
  SymbolModel changed_values_{64};
  LazyModels bit_byte_{256, 256}, classification_{256, 256}, user_data_{256, 256}, scan_angle_{2, 256};
  IntegerDecoder ic_intensity_{16, 4}, ic_point_source_{16, 1}, ic_dx_{32, 2}, ic_dy_{32, 22}, ic_z_{32, 20};
};

// GPSTIME11 v2 and the GPS time of POINT14 v3: the double's bits as an integer, predicted
// from up to four interleaved time sequences by a multiple of their last difference. v3 codes
// "unchanged" outside (a flag of the point), so its codes from "unchanged" on are one lower.
class GpsTimeDecoder {
 public:
  explicit GpsTimeDecoder(bool v3 = false)
      : v3_(v3), multi_(v3 ? kMultiTotal - 1 : kMultiTotal), zero_diff_(v3 ? 5 : 6) {}
  void first(ByteReader& in, unsigned char* out) {
    in.bytes(out, 8);
    time_[0] = get_u64(out);
  }
  void next(ArithmeticDecoder& dec, unsigned char* out) {
    // A switch to another sequence is followed by that sequence's own code: a loop, as the
    // switches could otherwise nest as deep as a corrupt stream likes.
    while (!decode_one(dec)) {
    }
    for (int i = 0; i < 8; ++i) out[i] = (unsigned char)(time_[last_] >> (8 * i));
  }
  std::uint64_t last() const { return time_[last_]; }
  void seed(std::uint64_t t) { time_[0] = t; }

 private:
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
  IntegerDecoder ic_{32, 9};
};

// The colour models of RGB12 v2 and RGB14 v3 (one set per scanner channel there).
struct RgbModels {
  SymbolModel byte_used{128};
  std::array<SymbolModel, 6> diff{SymbolModel(256), SymbolModel(256), SymbolModel(256),
                                  SymbolModel(256), SymbolModel(256), SymbolModel(256)};
};

// One colour: which bytes changed (bit 6: green and blue differ from red), then each changed
// byte as a correction of a prediction from red's change.
std::array<std::uint32_t, 3> decode_rgb(ArithmeticDecoder& dec, RgbModels& m, const std::array<std::uint32_t, 3>& last) {
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

std::array<std::uint32_t, 3> get_rgb(const unsigned char* p) { return {get_u16(p), get_u16(p + 2), get_u16(p + 4)}; }
void put_rgb(unsigned char* p, const std::array<std::uint32_t, 3>& c) {
  for (int i = 0; i < 3; ++i) put_u16(p + 2 * i, std::uint16_t(c[i]));
}

// RGB12 v2.
class RgbDecoder {
 public:
  void first(ByteReader& in, unsigned char* out) {
    in.bytes(out, 6);
    last_ = get_rgb(out);
  }
  void next(ArithmeticDecoder& dec, unsigned char* out) {
    last_ = decode_rgb(dec, models_, last_);
    put_rgb(out, last_);
  }

 private:
  std::array<std::uint32_t, 3> last_{};
  RgbModels models_;
};

// BYTE v2 (extra bytes): each byte as a difference to its previous value, one model per byte.
class BytesDecoder {
 public:
  explicit BytesDecoder(std::size_t n) : last_(n), models_(n, SymbolModel(256)) {}
  void first(ByteReader& in, unsigned char* out) {
    in.bytes(out, last_.size());
    std::copy(out, out + last_.size(), last_.begin());
  }
  void next(ArithmeticDecoder& dec, unsigned char* out) {
    for (std::size_t i = 0; i < last_.size(); ++i) out[i] = last_[i] = (unsigned char)(last_[i] + dec.symbol(models_[i]));
  }

 private:
  std::vector<unsigned char> last_;
  std::vector<SymbolModel> models_;
};

// One chunk of a pointwise-compressed (compressor 2) file: the first point raw, item after
// item, then one arithmetic stream for every later point.
class PointwiseChunk {
 public:
  PointwiseChunk(const std::vector<Item>& items, ByteReader& in) : items_(items), in_(in), dec_(in) {
    for (const Item& it : items) {
      if (it.type == kPoint10) point_.emplace();
      else if (it.type == kGpsTime11) time_.emplace();
      else if (it.type == kRgb12) rgb_.emplace();
      else bytes_.emplace(it.size);
    }
  }
  void decode(unsigned char* out) {
    unsigned char* p = out;
    for (const Item& it : items_) {
      if (first_) decode_item<true>(it.type, p);
      else decode_item<false>(it.type, p);
      p += it.size;
    }
    if (first_) dec_.init();
    first_ = false;
  }

 private:
  template <bool First>
  void decode_item(std::uint16_t type, unsigned char* p) {
    const auto one = [&](auto& d) {
      if constexpr (First) d.first(in_, p);
      else d.next(dec_, p);
    };
    switch (type) {
      case kPoint10: return one(*point_);
      case kGpsTime11: return one(*time_);
      case kRgb12: return one(*rgb_);
      default: return one(*bytes_);
    }
  }

  const std::vector<Item>& items_;
  ByteReader& in_;
  ArithmeticDecoder dec_;
  bool first_ = true;
  std::optional<Point10Decoder> point_;
  std::optional<GpsTimeDecoder> time_;
  std::optional<RgbDecoder> rgb_;
  std::optional<BytesDecoder> bytes_;
};

// ---- Layered compression (compressor 3, point formats 6–8): per chunk the first point raw,
// the chunk's point count, the byte size of every layer, then the layers, each its own
// arithmetic stream. Point fields keep one context per scanner channel.

// One layer of a chunk: its own byte range and decoder; an empty layer means "unchanged".
struct Layer {
  std::optional<ByteReader> bytes;
  std::optional<ArithmeticDecoder> dec;
  bool present() const { return dec.has_value(); }
  ArithmeticDecoder& operator*() {
    if (!dec) throw OutOfData{};  // a change coded in an empty layer: corrupt
    return *dec;
  }
  ArithmeticDecoder* operator->() { return &**this; }
};

// Contexts of POINT14 by (number of returns, return number): 6 for x/y, 8 levels for z.
constexpr unsigned char kReturnMap6[16][16] = {
    {0, 1, 2, 3, 4, 5, 3, 4, 4, 5, 5, 5, 5, 5, 5, 5}, {1, 0, 1, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3},
    {2, 1, 2, 4, 4, 4, 4, 4, 4, 4, 4, 3, 3, 3, 3, 3}, {3, 3, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4},
    {3, 3, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4, 4}, {4, 3, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4, 4},
    {4, 3, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4, 4}, {5, 3, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4, 4},
    {5, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 4, 4, 4, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 4, 4, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4, 4}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5, 4},
    {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5, 5}, {5, 3, 3, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 4, 5, 5}};
unsigned return_level8(unsigned n, unsigned r) {
  const unsigned d = n > r ? n - r : r - n;
  return std::min(d, 7u);
}

// The 30 bytes of formats 6–10: x, y, z, intensity, returns (r | n << 4), flags (class flags,
// channel << 4, scan direction << 6, edge << 7), class, user data, scan angle, source, time.
struct Point14Context {
  bool used = false;
  unsigned char last[30] = {};
  std::array<std::uint16_t, 8> last_intensity{};
  std::array<std::int32_t, 8> last_z{};
  std::array<Median5, 12> x_median, y_median;
  bool gps_changed = false;
  LazyModels changed_values{8, 128}, nr{16, 16}, rn{16, 16}, classification{64, 256}, flags{64, 64}, user_data{64, 256};
  SymbolModel scanner_channel{3}, rn_gps_same{13};
  IntegerDecoder ic_dx{32, 2}, ic_dy{32, 22}, ic_z{32, 20}, ic_intensity{16, 4}, ic_scan_angle{16, 2},
      ic_point_source{16, 1};
  GpsTimeDecoder time{true};

  // A channel's first point continues from the point before it, of whatever channel.
  void start_from(const unsigned char* point) {
    used = true;
    std::memcpy(last, point, 30);
    last_z.fill(std::int32_t(get_u32(point + 8)));
    last_intensity.fill(get_u16(point + 12));
    time.seed(get_u64(point + 22));
  }
};

// The layers of POINT14, in stream order.
enum Point14Layer { kXY, kZ, kClass, kFlags, kIntensity, kScanAngle, kUserData, kPointSource, kGpsTime, kLayers };

class Point14Decoder {
 public:
  int channel() const { return channel_; }
  void first(ByteReader& in, unsigned char* out) {
    in.bytes(out, 30);
    channel_ = (out[15] >> 4) & 3;
    context(channel_).start_from(out);
  }
  std::array<Layer, kLayers>& layers() { return layers_; }

  void next(unsigned char* out) {
    Point14Context& prev = context(channel_);
    const unsigned prev_r = prev.last[14] & 15, prev_n = prev.last[14] >> 4;
    ArithmeticDecoder& xy = *layers_[kXY];
    const unsigned change_stream = (prev_r == 1) | (prev_r >= prev_n) << 1 | unsigned(prev.gps_changed) << 2;
    const std::uint32_t changed = xy.symbol(prev.changed_values[change_stream]);
    const bool gps_changed = changed & 16;
    int channel = channel_;
    if (changed & 64) channel_ = channel = int((unsigned(channel) + xy.symbol(prev.scanner_channel) + 1) % 4);
    Point14Context& c = context(channel);
    if (!c.used) c.start_from(prev.last);
    unsigned char* p = c.last;
    p[15] = (unsigned char)((p[15] & ~0x30) | channel << 4);

    unsigned n = p[14] >> 4, r = p[14] & 15;
    if (changed & 4) n = xy.symbol(c.nr[n]);
    const bool rn_plus = changed & 1, rn_minus = changed & 2;
    if (rn_plus && !rn_minus) r = (r + 1) % 16;
    else if (rn_minus && !rn_plus) r = (r + 15) % 16;
    else if (rn_plus && rn_minus) r = gps_changed ? xy.symbol(c.rn[r]) : (r + xy.symbol(c.rn_gps_same) + 2) % 16;
    p[14] = (unsigned char)(r | n << 4);

    const unsigned ctx = unsigned(kReturnMap6[n][r]) << 1 | unsigned(gps_changed);
    const std::uint32_t single = n == 1;
    const std::int32_t dx = c.ic_dx.decode(xy, c.x_median[ctx].get(), single);
    put_u32(p, get_u32(p) + std::uint32_t(dx));
    c.x_median[ctx].add(dx);
    const std::int32_t dy = c.ic_dy.decode(xy, c.y_median[ctx].get(), single | (std::min(c.ic_dx.k(), 20u) & ~1u));
    put_u32(p + 4, get_u32(p + 4) + std::uint32_t(dy));
    c.y_median[ctx].add(dy);
    if (layers_[kZ].present()) {
      const std::uint32_t k = std::min((c.ic_dx.k() + c.ic_dy.k()) / 2, 18u) & ~1u;
      const unsigned level = return_level8(n, r);
      c.last_z[level] = c.ic_z.decode(*layers_[kZ], c.last_z[level], single | k);
      put_u32(p + 8, std::uint32_t(c.last_z[level]));
    }
    if (layers_[kClass].present())
      p[16] = (unsigned char)layers_[kClass]->symbol(c.classification[unsigned(r == 1 && r >= n) | (p[16] & 0x1f) << 1]);
    if (layers_[kFlags].present()) {
      const unsigned merged = (p[15] & 15) | (p[15] >> 6 & 1) << 4 | (p[15] >> 7) << 5;
      const std::uint32_t f = layers_[kFlags]->symbol(c.flags[merged]);
      p[15] = (unsigned char)((f & 15) | (p[15] & 0x30) | (f >> 4 & 1) << 6 | (f >> 5 & 1) << 7);
    }
    if (layers_[kIntensity].present()) {
      const unsigned i = unsigned(gps_changed) | unsigned(r >= n) << 1 | unsigned(r == 1) << 2;
      c.last_intensity[i] = std::uint16_t(c.ic_intensity.decode(*layers_[kIntensity], c.last_intensity[i], i >> 1));
      put_u16(p + 12, c.last_intensity[i]);
    }
    if (changed & 8)
      put_u16(p + 18, std::uint16_t(c.ic_scan_angle.decode(*layers_[kScanAngle], std::int16_t(get_u16(p + 18)), gps_changed)));
    if (layers_[kUserData].present()) p[17] = (unsigned char)layers_[kUserData]->symbol(c.user_data[p[17] / 4]);
    if (changed & 32) put_u16(p + 20, std::uint16_t(c.ic_point_source.decode(*layers_[kPointSource], get_u16(p + 20), 0)));
    if (gps_changed) c.time.next(*layers_[kGpsTime], p + 22);
    c.gps_changed = gps_changed;
    std::memcpy(out, p, 30);
  }

 private:
  // Contexts are made on a channel's first point: most files use one channel.
  Point14Context& context(int channel) {
    if (!ctx_[channel]) ctx_[channel] = std::make_unique<Point14Context>();
    return *ctx_[channel];
  }

  std::array<std::unique_ptr<Point14Context>, 4> ctx_;
  std::array<Layer, kLayers> layers_;
  int channel_ = 0;
};

// RGB14 / RGBNIR14 and BYTE14 keep their models and last values per scanner channel too. As
// LASzip's v3 readers do (and laz-perf): a channel's first point continues from the channel
// before it; after a switch back to a channel already seen in the chunk, the prediction still
// comes from (and updates) the previous channel's last value, with the new channel's models.
template <class Last, class Models>
class ChannelState {
 public:
  void first(int channel, const Last& value, std::unique_ptr<Models> models) {
    current_ = channel;
    ctx_[channel].used = true;
    ctx_[channel].last = value;
    ctx_[channel].models = std::move(models);
  }
  // The last value to predict from for a point of `channel`; makes its context when new.
  Last& select(int channel, const std::function<std::unique_ptr<Models>()>& make) {
    Last* last = &ctx_[current_].last;
    if (channel != current_) {
      current_ = channel;
      if (!ctx_[channel].used) {
        ctx_[channel].used = true;
        ctx_[channel].last = *last;
        ctx_[channel].models = make();
        last = &ctx_[channel].last;
      }
    }
    return *last;
  }
  Models& models() { return *ctx_[current_].models; }
  Last& current_last() { return ctx_[current_].last; }

 private:
  struct Context {
    bool used = false;
    Last last{};
    std::unique_ptr<Models> models;
  };
  std::array<Context, 4> ctx_;
  int current_ = 0;
};

struct NirModels {
  SymbolModel byte_used{4};
  std::array<SymbolModel, 2> diff{SymbolModel(256), SymbolModel(256)};
};

// RGB14 (6 bytes) or RGBNIR14 (8 bytes: the colour and the near infrared, two layers).
class Rgb14Decoder {
 public:
  explicit Rgb14Decoder(bool nir) : nir_(nir) {}
  void first(ByteReader& in, unsigned char* out, int channel) {
    in.bytes(out, nir_ ? 8 : 6);
    state_.first(channel, {get_rgb(out), nir_ ? get_u16(out + 6) : 0u}, make());
  }
  std::array<Layer, 2>& layers() { return layers_; }
  void next(unsigned char* out, int channel) {
    Last& last = state_.select(channel, make);
    if (layers_[0].present()) last.rgb = decode_rgb(*layers_[0], state_.models().rgb, last.rgb);
    put_rgb(out, last.rgb);
    if (!nir_) return;
    // LASzip predicts the infrared from the same last value, but keeps it in the current channel.
    std::uint32_t& kept = state_.current_last().nir;
    if (layers_[1].present()) {
      ArithmeticDecoder& dec = *layers_[1];
      NirModels& m = state_.models().nir;
      const std::uint32_t sym = dec.symbol(m.byte_used);
      std::uint32_t v = sym & 1 ? (dec.symbol(m.diff[0]) + last.nir) & 0xff : last.nir & 0xff;
      v |= sym & 2 ? ((dec.symbol(m.diff[1]) + (last.nir >> 8)) & 0xff) << 8 : last.nir & 0xff00;
      kept = v;
    }
    put_u16(out + 6, std::uint16_t(kept));
  }

 private:
  struct Last {
    std::array<std::uint32_t, 3> rgb{};
    std::uint32_t nir = 0;
  };
  struct Models {
    RgbModels rgb;
    NirModels nir;
  };
  static std::unique_ptr<Models> make() { return std::make_unique<Models>(); }

  bool nir_;
  ChannelState<Last, Models> state_;
  std::array<Layer, 2> layers_;
};

// BYTE14: each extra byte its own layer, a difference to its last value.
class Byte14Decoder {
 public:
  explicit Byte14Decoder(std::size_t n) : layers_(n) {}
  void first(ByteReader& in, unsigned char* out, int channel) {
    std::vector<unsigned char> v(layers_.size());
    in.bytes(v.data(), v.size());
    std::copy(v.begin(), v.end(), out);
    state_.first(channel, v, make(v.size()));
  }
  std::vector<Layer>& layers() { return layers_; }
  void next(unsigned char* out, int channel) {
    const std::size_t n = layers_.size();
    std::vector<unsigned char>& last = state_.select(channel, [n] { return make(n); });
    for (std::size_t i = 0; i < n; ++i) {
      if (layers_[i].present()) last[i] = (unsigned char)(last[i] + layers_[i]->symbol(state_.models()[i]));
      out[i] = last[i];
    }
  }

 private:
  using Models = std::vector<SymbolModel>;
  static std::unique_ptr<Models> make(std::size_t n) { return std::make_unique<Models>(n, SymbolModel(256)); }

  std::vector<Layer> layers_;
  ChannelState<std::vector<unsigned char>, Models> state_;
};

// One chunk of a layered (compressor 3) file.
class LayeredChunk {
 public:
  LayeredChunk(const std::vector<Item>& items, ByteReader& in) : in_(in) {
    for (const Item& it : items) {
      if (it.type == kRgb14 || it.type == kRgbNir14) rgb_.emplace(it.type == kRgbNir14), rgb_size_ = it.size;
      else if (it.type == kByte14) bytes_.emplace(it.size);
    }
  }
  void decode(unsigned char* out) {
    if (first_) return decode_first(out);
    point_.next(out);
    const int ch = point_.channel();
    if (rgb_) rgb_->next(out + 30, ch);
    if (bytes_) bytes_->next(out + 30 + rgb_size_, ch);
  }

 private:
  // The raw first point, then the count, the layer sizes and the layers themselves.
  void decode_first(unsigned char* out) {
    first_ = false;
    point_.first(in_, out);
    const int ch = point_.channel();
    if (rgb_) rgb_->first(in_, out + 30, ch);
    if (bytes_) bytes_->first(in_, out + 30 + rgb_size_, ch);
    unsigned char b[4];
    in_.bytes(b, 4);  // the chunk's point count: the chunk table's is used
    std::vector<std::pair<Layer*, std::uint32_t>> sizes;
    for (Layer& l : point_.layers()) sizes.push_back({&l, read_u32()});
    if (rgb_) {
      sizes.push_back({&rgb_->layers()[0], read_u32()});
      if (rgb_size_ == 8) sizes.push_back({&rgb_->layers()[1], read_u32()});
    }
    if (bytes_)
      for (Layer& l : bytes_->layers()) sizes.push_back({&l, read_u32()});
    for (auto& [layer, size] : sizes) {
      if (size == 0) continue;
      const unsigned char* start = in_.take(size);
      layer->bytes.emplace(start, start + size);
      layer->dec.emplace(*layer->bytes);
      layer->dec->init();
    }
  }
  std::uint32_t read_u32() {
    unsigned char b[4];
    in_.bytes(b, 4);
    return get_u32(b);
  }

  ByteReader& in_;
  bool first_ = true;
  Point14Decoder point_;
  std::optional<Rgb14Decoder> rgb_;
  std::optional<Byte14Decoder> bytes_;
  std::size_t rgb_size_ = 0;
};


// The items a point format needs, in record order (extra bytes come last, as one BYTE item):
// version 2 items for formats 0–5 (compressor 2), version 3 for 6–10 (compressor 3).
std::string check_items(const std::vector<Item>& items, int format, std::uint16_t compressor,
                        std::uint32_t record_length) {
  const bool layered = format >= 6;
  if (compressor != (layered ? 3 : 2))
    return "LASzip compressor " + std::to_string(compressor) + " does not fit point format " + std::to_string(format);
  std::vector<std::uint16_t> want;
  if (layered) {
    want = {kPoint14};
    if (format == 7) want.push_back(kRgb14);
    if (format == 8 || format == 10) want.push_back(kRgbNir14);
  } else {
    want = {kPoint10};
    if (format == 1 || format == 3 || format == 4 || format == 5) want.push_back(kGpsTime11);
    if (format == 2 || format == 3 || format == 5) want.push_back(kRgb12);
  }
  const std::uint16_t bytes_type = layered ? kByte14 : kByte, version = layered ? 3 : 2;
  std::uint32_t total = 0;
  std::size_t i = 0;
  for (const Item& it : items) {
    if (it.type == kWavePacket13 || it.type == kWavePacket14)
      return "waveform packets (point formats 4, 5, 9 and 10) are not supported in LAZ";
    const bool expected = i < want.size() ? it.type == want[i] : it.type == bytes_type && i == want.size();
    if (!expected)
      return "LASzip item type " + std::to_string(it.type) + " does not fit point format " + std::to_string(format);
    if (it.version != version)
      return "LASzip item version " + std::to_string(it.version) + " (point format " + std::to_string(format) +
             " is read in version " + std::to_string(version) + ")";
    static const std::array<std::uint16_t, 15> kSize = {0, 0, 0, 0, 0, 0, 20, 8, 6, 0, 30, 6, 8, 0, 0};
    const std::uint16_t size = it.type == bytes_type ? it.size : kSize[it.type];
    if (it.size != size || size == 0)
      return "LASzip item type " + std::to_string(it.type) + " of " + std::to_string(it.size) + " bytes";
    total += it.size;
    ++i;
  }
  if (i < want.size()) return "LASzip items do not cover point format " + std::to_string(format);
  if (total != record_length)
    return "LASzip items hold " + std::to_string(total) + " bytes per point, the header " +
           std::to_string(record_length);
  return {};
}

// Reads the chunk table one entry at a time: (points, compressed bytes) per chunk.
class ChunkTable {
 public:
  ChunkTable(const std::string& path, std::ifstream& in, std::uint64_t file_size, const Layout& layout)
      : layout_(layout) {
    // An entry takes at most a few bytes; the table never needs more than this many.
    const std::uint64_t start = layout.table_offset + 8;
    const std::uint64_t want = std::min<std::uint64_t>(file_size - std::min(file_size, start),
                                                       16 * std::uint64_t(layout.chunk_count) + 64);
    bytes_.resize(std::size_t(want));
    if (!read_at(in, start, bytes_.data(), bytes_.size())) fail(path, "read error in the LAZ chunk table");
    reader_.emplace(bytes_.data(), bytes_.data() + bytes_.size());
    dec_.emplace(*reader_);
  }
  // Points and bytes of the next chunk; throws OutOfData on a truncated table.
  std::pair<std::uint32_t, std::uint32_t> next() {
    if (!started_) dec_->init(), started_ = true;
    std::uint32_t count = layout_.chunk_size;
    if (layout_.chunk_size == kVariableChunks) count = prev_count_ = std::uint32_t(ic_.decode(*dec_, std::int32_t(prev_count_), 0));
    prev_bytes_ = std::uint32_t(ic_.decode(*dec_, std::int32_t(prev_bytes_), 1));
    return {count, prev_bytes_};
  }

 private:
  const Layout& layout_;
  std::vector<unsigned char> bytes_;
  std::optional<ByteReader> reader_;
  std::optional<ArithmeticDecoder> dec_;
  IntegerDecoder ic_{32, 2};
  bool started_ = false;
  std::uint32_t prev_count_ = 0, prev_bytes_ = 0;
};

}  // namespace

Layout read_layout(const std::string& path, std::ifstream& in, std::uint64_t file_size, const LasHeader& h,
                   const std::string& vlr) {
  const auto* v = reinterpret_cast<const unsigned char*>(vlr.data());
  if (vlr.size() < 34) fail(path, "LASzip VLR of " + std::to_string(vlr.size()) + " bytes (at least 34 needed)");
  Layout L;
  L.compressor = get_u16(v);
  L.chunk_size = get_u32(v + 12);
  const std::uint16_t n_items = get_u16(v + 32);
  if (vlr.size() < 34 + 6 * std::size_t(n_items)) fail(path, "LASzip VLR truncated: its item list does not fit");
  for (std::uint16_t i = 0; i < n_items; ++i)
    L.items.push_back({get_u16(v + 34 + 6 * i), get_u16(v + 36 + 6 * i), get_u16(v + 38 + 6 * i)});
  if (L.compressor != 2 && L.compressor != 3)
    fail(path, "LASzip compressor " + std::to_string(L.compressor) +
                   " is not supported (2, chunked pointwise, and 3, chunked layered, are read)");
  if (const std::string bad = check_items(L.items, h.point_format, L.compressor, h.record_length); !bad.empty())
    fail(path, bad);
  if (L.chunk_size == 0) fail(path, "LASzip chunk size 0");

  unsigned char b[8];
  if (h.point_offset + 8 > file_size || !read_at(in, h.point_offset, b, 8))
    fail(path, "LAZ point data ends before its chunk table offset (truncated?)");
  std::uint64_t table = get_u64(b);
  if (table == ~std::uint64_t(0)) {  // written to a stream: the offset is the file's last 8 bytes
    if (file_size < 8 || !read_at(in, file_size - 8, b, 8)) fail(path, "LAZ chunk table offset missing");
    table = get_u64(b);
  }
  const std::uint64_t first_chunk = h.point_offset + 8;
  if (table < first_chunk || table > file_size || file_size - table < 8)
    fail(path, "LAZ chunk table offset " + std::to_string(table) + " lies outside the point data (file of " +
                   std::to_string(file_size) + " bytes; truncated?)");
  L.table_offset = table;
  if (!read_at(in, table, b, 8)) fail(path, "read error in the LAZ chunk table");
  if (get_u32(b) != 0) fail(path, "LAZ chunk table version " + std::to_string(get_u32(b)) + " (0 expected)");
  L.chunk_count = get_u32(b + 4);
  // Every chunk starts with one raw point, so the point data bounds the number of chunks.
  const std::uint64_t max_chunks = (table - first_chunk) / h.record_length;
  if (L.chunk_count > max_chunks)
    fail(path, "LAZ chunk table declares " + std::to_string(L.chunk_count) + " chunks but " +
                   std::to_string(table - first_chunk) + " bytes of point data hold at most " +
                   std::to_string(max_chunks));
  if (h.point_count > 0 && L.chunk_count == 0) fail(path, "LAZ chunk table is empty but the header declares points");

  // Walk the table: every chunk inside the point data, enough points for the header.
  ChunkTable t(path, in, file_size, L);
  std::uint64_t points = 0, pos = first_chunk;
  try {
    for (std::uint32_t i = 0; i < L.chunk_count && points < h.point_count; ++i) {
      const auto [count, bytes] = t.next();
      if (count == 0) fail(path, "LAZ chunk " + std::to_string(i) + " holds no points");
      if (bytes < h.record_length || bytes > table - pos)
        fail(path, "LAZ chunk " + std::to_string(i) + " of " + std::to_string(bytes) + " bytes at offset " +
                       std::to_string(pos) + " does not fit the point data before the chunk table at " +
                       std::to_string(table));
      points += count;
      pos += bytes;
    }
  } catch (const OutOfData&) {
    fail(path, "LAZ chunk table truncated or corrupt");
  }
  if (points < h.point_count)
    fail(path, "header declares " + std::to_string(h.point_count) + " points but the LAZ chunks hold only " +
                   std::to_string(points) + " (truncated?)");
  return L;
}

void stream_records(const std::string& path, std::ifstream& in, std::uint64_t file_size, const LasHeader& h,
                    const Layout& L, const std::function<void(const unsigned char*)>& on_record) {
  ChunkTable table(path, in, file_size, L);
  std::vector<unsigned char> chunk, record(h.record_length);
  std::uint64_t pos = h.point_offset + 8, done = 0;
  for (std::uint32_t i = 0; done < h.point_count; ++i) {
    if (i >= L.chunk_count) fail(path, "LAZ chunk table changed while reading (file modified?)");
    std::pair<std::uint32_t, std::uint32_t> entry;
    try {
      entry = table.next();
    } catch (const OutOfData&) {
      fail(path, "LAZ chunk table truncated or corrupt");
    }
    chunk.resize(entry.second);
    if (!read_at(in, pos, chunk.data(), chunk.size())) fail(path, "LAZ chunk " + std::to_string(i) + " truncated");
    pos += entry.second;
    ByteReader reader(chunk.data(), chunk.data() + chunk.size());
    const std::uint64_t n = std::min<std::uint64_t>(entry.first, h.point_count - done);
    const auto decode_all = [&](auto&& decoder) {
      for (std::uint64_t k = 0; k < n; ++k, ++done) {
        decoder.decode(record.data());
        on_record(record.data());
      }
    };
    try {
      if (L.compressor == 3) decode_all(LayeredChunk(L.items, reader));
      else decode_all(PointwiseChunk(L.items, reader));
    } catch (const OutOfData&) {
      fail(path, "LAZ chunk " + std::to_string(i) + " ends after " + std::to_string(done) + " of " +
                     std::to_string(h.point_count) + " points (truncated or corrupt)");
    }
  }
}

}  // namespace lodrefine::laz
