// Internal to the laz library's LAZ codec (laz.h, laz_write.cpp): LASzip's arithmetic decoder and
// encoder, their shared adaptive bit and symbol models and the integer coder (one set of
// models, decoded from or encoded into), after the published LASzip format, plus the byte
// reader they decode from. All state is unsigned where the format wraps (corrector sums), so no
// signed overflow or negative shift happens on any input.
#pragma once
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "lodrefine/base/text.h"

namespace lodrefine::laz {

// The decoder ran past the bytes its chunk (or table) holds: the data is truncated or corrupt.
struct OutOfData {};
// The chunk's data codes something no LASzip encoder writes and that would cost unbounded time or
// memory to follow; `what` says what, for the error line.
struct Corrupt {
  const char* what;
};

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

constexpr std::uint32_t kMinLength = 0x01000000u;  // renormalise below this interval length
constexpr std::uint32_t kBitLengthShift = 13;      // bit models: probabilities of 13 bits
constexpr std::uint32_t kBitMaxCount = 1u << 13;
constexpr std::uint32_t kSymbolLengthShift = 15;  // symbol models: distributions of 15 bits
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

// LASzip's arithmetic encoder (the decoder's inverse): appends to `out`; a carry runs back over
// the bytes already written. done() flushes the interval with the padding the decoder reads.
class ArithmeticEncoder {
 public:
  explicit ArithmeticEncoder(std::vector<unsigned char>& out) : out_(out), start_(out.size()) {}
  void bit(BitModel& m, std::uint32_t sym) {
    const std::uint32_t x = m.bit_0_prob * (length_ >> kBitLengthShift);
    if (sym == 0) {
      length_ = x;
      ++m.bit_0_count;
    } else {
      add(x);
      length_ -= x;
    }
    if (length_ < kMinLength) renormalise();
    if (--m.until_update == 0) m.update();
  }
  void symbol(SymbolModel& m, std::uint32_t sym) {
    if (sym + 1 == m.symbols) {  // the last symbol takes the rest of the interval
      const std::uint32_t x = m.distribution[sym] * (length_ >> kSymbolLengthShift);
      add(x);
      length_ -= x;
    } else {
      const std::uint32_t x = m.distribution[sym] * (length_ >>= kSymbolLengthShift);
      add(x);
      length_ = m.distribution[sym + 1] * length_ - x;
    }
    if (length_ < kMinLength) renormalise();
    ++m.count[sym];
    if (--m.until_update == 0) m.update();
  }
  // `bits` (1..32) raw bits of `sym`, low 16 first when over 19 (as the decoder reads them).
  void bits(std::uint32_t bits, std::uint32_t sym) {
    if (bits > 19) {
      raw(16, sym & 0xffff);
      sym >>= 16;
      bits -= 16;
    }
    raw(bits, sym);
  }
  void u32(std::uint32_t v) {
    raw(16, v & 0xffff);
    raw(16, v >> 16);
  }
  void done() {
    const std::uint32_t init = base_;
    const bool another_byte = length_ > 2 * kMinLength;
    if (another_byte) {
      base_ += kMinLength;
      length_ = kMinLength >> 1;
    } else {
      base_ += kMinLength >> 1;
      length_ = kMinLength >> 9;
    }
    if (init > base_) carry();
    renormalise();
    out_.insert(out_.end(), another_byte ? 3 : 2, 0);  // the decoder reads ahead
  }

 private:
  void raw(std::uint32_t bits, std::uint32_t sym) {
    add(sym * (length_ >>= bits));
    if (length_ < kMinLength) renormalise();
  }
  void add(std::uint32_t x) {
    const std::uint32_t init = base_;
    base_ += x;
    if (init > base_) carry();
  }
  void carry() {
    std::size_t i = out_.size();
    while (i > start_ && out_[i - 1] == 0xff) out_[--i] = 0;
    if (i > start_) ++out_[i - 1];
  }
  void renormalise() {
    do {
      out_.push_back((unsigned char)(base_ >> 24));
      base_ <<= 8;
    } while ((length_ <<= 8) < kMinLength);
  }

  std::vector<unsigned char>& out_;
  std::size_t start_;
  std::uint32_t base_ = 0, length_ = 0xffffffffu;
};

// LASzip's integer compressor and decompressor: a value is a prediction plus a corrector whose
// bit length k is coded per context, then its bits (the high ones modelled, the rest raw). The
// corrector wraps into its range both ways, so every value of `bits` bits round-trips.
class IntegerCoder {
 public:
  explicit IntegerCoder(std::uint32_t bits = 16, std::uint32_t contexts = 1, std::uint32_t bits_high = 8)
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
  // Codes `real` (a value of `bits` bits, signed or not as the caller's prediction) given `pred`.
  void encode(ArithmeticEncoder& enc, std::int32_t pred, std::int32_t real, std::uint32_t context) {
    std::int32_t corr = std::int32_t(std::uint32_t(real) - std::uint32_t(pred));  // 32 bits: wraps
    if (corr_range_ != 0) {
      const std::int64_t c = std::int64_t(real) - pred, range = corr_range_;
      corr = std::int32_t(c < corr_min_ ? c + range : c > corr_min_ + range - 1 ? c - range : c);
    }
    write_corrector(enc, corr, k_models_[context]);
  }
  std::uint32_t k() const { return k_; }

 private:
  // The corrector model of each bit length is made on first use (LASzip makes all at once; an
  // unused model's state never matters).
  SymbolModel& corrector_model(std::uint32_t k) {
    std::unique_ptr<SymbolModel>& model = corrector_[k - 1];
    if (!model) model = std::make_unique<SymbolModel>(1u << std::min(k, bits_high_));
    return *model;
  }
  std::int32_t corrector(ArithmeticDecoder& dec, SymbolModel& k_model) {
    k_ = dec.symbol(k_model);
    if (k_ == 0) return std::int32_t(dec.bit(corrector0_));  // 0 or 1
    if (k_ >= 32) return corr_min_;
    std::uint32_t c = dec.symbol(corrector_model(k_));
    if (k_ > bits_high_) {
      const std::uint32_t low_bits = k_ - bits_high_;
      c = (c << low_bits) | dec.bits(low_bits);
    }
    // c in [2^(k-1), 2^k) stands for c + 1; c in [0, 2^(k-1)) for c - (2^k - 1).
    return std::int32_t(c >= (1u << (k_ - 1)) ? c + 1 : c - ((1u << k_) - 1));
  }
  // k: the smallest with c in [-(2^k - 1), 2^k]; then c mapped into [0, 2^k) as above.
  void write_corrector(ArithmeticEncoder& enc, std::int32_t c, SymbolModel& k_model) {
    std::uint32_t c1 = c <= 0 ? 0u - std::uint32_t(c) : std::uint32_t(c) - 1;
    k_ = 0;
    while (c1) c1 >>= 1, ++k_;
    enc.symbol(k_model, k_);
    if (k_ == 0) return enc.bit(corrector0_, std::uint32_t(c));
    if (k_ >= 32) return;
    const std::uint32_t v = c < 0 ? std::uint32_t(c) + ((1u << k_) - 1) : std::uint32_t(c) - 1;
    if (k_ <= bits_high_) return enc.symbol(corrector_model(k_), v);
    const std::uint32_t low_bits = k_ - bits_high_;
    enc.symbol(corrector_model(k_), v >> low_bits);
    enc.bits(low_bits, v & ((1u << low_bits) - 1));
  }

  std::uint32_t bits_high_, corr_bits_ = 32, corr_range_ = 0;
  std::int32_t corr_min_ = 0;
  std::uint32_t k_ = 0;
  std::vector<SymbolModel> k_models_;
  BitModel corrector0_;
  std::vector<std::unique_ptr<SymbolModel>> corrector_;
};

inline std::uint16_t get_u16(const unsigned char* p) { return io_text::get_le<std::uint16_t>(p); }
inline std::uint32_t get_u32(const unsigned char* p) { return io_text::get_le<std::uint32_t>(p); }
inline std::uint64_t get_u64(const unsigned char* p) { return io_text::get_le<std::uint64_t>(p); }
inline void put_u32(unsigned char* p, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = (unsigned char)(v >> (8 * i));
}
inline void put_u16(unsigned char* p, std::uint16_t v) { p[0] = (unsigned char)v, p[1] = (unsigned char)(v >> 8); }

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

}  // namespace lodrefine::laz
