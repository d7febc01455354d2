// LAZ compressor 2 (chunked, pointwise; point formats 0-5): the version-2 item coders of
// POINT10, GPSTIME11, RGB12 and BYTE and WAVEPACKET13 v1 (one state and set of models each, decoded from or encoded
// into), and one chunk's decoding and encoding (laz_items.h).
#include <array>
#include <cstring>
#include <optional>

#include "laz_items.h"

namespace lodrefine::laz {
namespace {

// Context tables of POINT10 v2 by (number of returns, return number): 16 contexts for the
// intensity and x/y medians, 8 levels for the z prediction. Files that number returns from 0
// or swap the two fields still get distinct contexts.
constexpr unsigned char kReturnMap[8][8] = {{15, 14, 13, 12, 11, 10, 9, 8},  {14, 0, 1, 3, 6, 10, 10, 9},
                                            {13, 1, 2, 4, 7, 11, 11, 10},    {12, 3, 4, 5, 8, 12, 12, 11},
                                            {11, 6, 7, 8, 9, 13, 13, 12},    {10, 10, 11, 12, 13, 14, 14, 13},
                                            {9, 10, 11, 12, 13, 14, 15, 14}, {8, 9, 10, 11, 12, 13, 14, 15}};
constexpr unsigned char kReturnLevel[8][8] = {
    {0, 1, 2, 3, 4, 5, 6, 7}, {1, 0, 1, 2, 3, 4, 5, 6}, {2, 1, 0, 1, 2, 3, 4, 5}, {3, 2, 1, 0, 1, 2, 3, 4},
    {4, 3, 2, 1, 0, 1, 2, 3}, {5, 4, 3, 2, 1, 0, 1, 2}, {6, 5, 4, 3, 2, 1, 0, 1}, {7, 6, 5, 4, 3, 2, 1, 0}};
// POINT10 v2: the 20 bytes of formats 0–5 (x, y, z, intensity, return bits, class, scan
// angle, user data, point source).
class Point10Coder {
 public:
  void start(const unsigned char* first) {
    std::memcpy(last_, first, 20);
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
  // LASzip's writer: a mask of the fields that differ, each of them, then x, y and z.
  void encode(ArithmeticEncoder& enc, const unsigned char* item) {
    const unsigned r = item[14] & 7, n = (item[14] >> 3) & 7;
    const unsigned m = kReturnMap[n][r], l = kReturnLevel[n][r];
    const std::uint16_t intensity = get_u16(item + 12), source = get_u16(item + 18);
    const std::uint32_t changed =
        std::uint32_t(item[14] != last_[14]) << 5 | std::uint32_t(intensity != last_intensity_[m]) << 4 |
        std::uint32_t(item[15] != last_[15]) << 3 | std::uint32_t(item[16] != last_[16]) << 2 |
        std::uint32_t(item[17] != last_[17]) << 1 | std::uint32_t(source != get_u16(last_ + 18));
    enc.symbol(changed_values_, changed);
    if (changed & 32) enc.symbol(bit_byte_[last_[14]], item[14]);
    if (changed & 16) {
      ic_intensity_.encode(enc, last_intensity_[m], intensity, m < 3 ? m : 3);
      last_intensity_[m] = intensity;
    }
    if (changed & 8) enc.symbol(classification_[last_[15]], item[15]);
    if (changed & 4) enc.symbol(scan_angle_[(item[14] >> 6) & 1], std::uint32_t(item[16] - last_[16]) & 0xff);
    if (changed & 2) enc.symbol(user_data_[last_[17]], item[17]);
    if (changed & 1) ic_point_source_.encode(enc, get_u16(last_ + 18), source, 0);
    const std::uint32_t single = n == 1;
    const auto dx = std::int32_t(get_u32(item) - get_u32(last_)),
               dy = std::int32_t(get_u32(item + 4) - get_u32(last_ + 4));
    ic_dx_.encode(enc, x_median_[m].get(), dx, single);
    x_median_[m].add(dx);
    const std::uint32_t kx = ic_dx_.k();
    ic_dy_.encode(enc, y_median_[m].get(), dy, single + (kx < 20 ? kx & ~1u : 20));
    y_median_[m].add(dy);
    const std::uint32_t kz = (ic_dx_.k() + ic_dy_.k()) / 2;
    const auto z = std::int32_t(get_u32(item + 8));
    ic_z_.encode(enc, last_height_[l], z, single + (kz < 18 ? kz & ~1u : 18));
    last_height_[l] = z;
    std::memcpy(last_, item, 20);
  }

 private:
  unsigned char last_[20] = {};
  std::uint16_t last_intensity_value_ = 0;
  std::array<std::uint16_t, 16> last_intensity_{};
  std::array<Median5, 16> x_median_, y_median_;
  std::array<std::int32_t, 8> last_height_{};
  SymbolModel changed_values_{64};
  LazyModels bit_byte_{256, 256}, classification_{256, 256}, user_data_{256, 256}, scan_angle_{2, 256};
  IntegerCoder ic_intensity_{16, 4}, ic_point_source_{16, 1}, ic_dx_{32, 2}, ic_dy_{32, 22}, ic_z_{32, 20};
};

// GPSTIME11 v2.
class GpsTime11Coder {
 public:
  void start(const unsigned char* first) { time_.seed(get_u64(first)); }
  void next(ArithmeticDecoder& dec, unsigned char* out) { time_.next(dec, out); }
  void encode(ArithmeticEncoder& enc, const unsigned char* item) { time_.encode(enc, get_u64(item)); }

 private:
  GpsTimeCoder time_;
};

// RGB12 v2.
class RgbCoder {
 public:
  void start(const unsigned char* first) { last_ = get_rgb(first); }
  void next(ArithmeticDecoder& dec, unsigned char* out) {
    last_ = decode_rgb(dec, models_, last_);
    put_rgb(out, last_);
  }
  void encode(ArithmeticEncoder& enc, const unsigned char* item) {
    encode_rgb(enc, models_, last_, get_rgb(item));
    last_ = get_rgb(item);
  }

 private:
  std::array<std::uint32_t, 3> last_{};
  RgbModels models_;
};

// WAVEPACKET13 v1 (formats 4 and 5: the waveform packet descriptor of the point).
class WavePacket13Coder {
 public:
  void start(const unsigned char* first) { std::memcpy(last_, first, kWavePacketSize); }
  void next(ArithmeticDecoder& dec, unsigned char* out) {
    decode_wavepacket(dec, models_, last_, out);
    std::memcpy(last_, out, kWavePacketSize);
  }
  void encode(ArithmeticEncoder& enc, const unsigned char* item) {
    encode_wavepacket(enc, models_, last_, item);
    std::memcpy(last_, item, kWavePacketSize);
  }

 private:
  unsigned char last_[kWavePacketSize] = {};
  WavePacketModels models_;
};

// BYTE v2 (extra bytes): each byte as a difference to its previous value, one model per byte,
// made on the chunk's second point (a chunk of one point, the first raw, needs none: 65,515 extra
// bytes cost 138 MB a chunk).
class BytesCoder {
 public:
  explicit BytesCoder(std::size_t n) : last_(n) {}
  void start(const unsigned char* first) { std::copy(first, first + last_.size(), last_.begin()); }
  void next(ArithmeticDecoder& dec, unsigned char* out) {
    make_models();
    for (std::size_t i = 0; i < last_.size(); ++i)
      out[i] = last_[i] = (unsigned char)(last_[i] + dec.symbol(models_[i]));
  }
  void encode(ArithmeticEncoder& enc, const unsigned char* item) {
    make_models();
    for (std::size_t i = 0; i < last_.size(); ++i) {
      enc.symbol(models_[i], std::uint32_t(item[i] - last_[i]) & 0xff);
      last_[i] = item[i];
    }
  }

 private:
  void make_models() {
    if (models_.empty()) models_.assign(last_.size(), SymbolModel(256));
  }
  std::vector<unsigned char> last_;
  std::vector<SymbolModel> models_;
};

// The coders of one chunk of a pointwise-compressed (compressor 2) file, in item order.
class PointwiseItems {
 public:
  explicit PointwiseItems(const std::vector<Item>& items) : items_(items) {
    for (const Item& it : items) {
      if (it.type == kPoint10) point_.emplace();
      else if (it.type == kGpsTime11) time_.emplace();
      else if (it.type == kRgb12) rgb_.emplace();
      else if (it.type == kWavePacket13) wave_.emplace();
      else bytes_.emplace(it.size);
    }
  }
  // Calls f(coder, item offset in the record, item bytes) for every item.
  template <class F>
  void each(F&& f) {
    std::size_t at = 0;
    for (const Item& it : items_) {
      switch (it.type) {
        case kPoint10: f(*point_, at, it.size); break;
        case kGpsTime11: f(*time_, at, it.size); break;
        case kRgb12: f(*rgb_, at, it.size); break;
        case kWavePacket13: f(*wave_, at, it.size); break;
        default: f(*bytes_, at, it.size);
      }
      at += it.size;
    }
  }

 private:
  const std::vector<Item>& items_;
  std::optional<Point10Coder> point_;
  std::optional<GpsTime11Coder> time_;
  std::optional<RgbCoder> rgb_;
  std::optional<WavePacket13Coder> wave_;
  std::optional<BytesCoder> bytes_;
};

// One chunk: the first point raw, item after item, then one arithmetic stream for every later
// point.
class PointwiseChunk {
 public:
  PointwiseChunk(const std::vector<Item>& items, ByteReader& in) : coders_(items), in_(in), dec_(in) {}
  void decode(unsigned char* out) {
    if (first_) {
      coders_.each([&](auto& c, std::size_t at, std::size_t size) {
        in_.bytes(out + at, size);
        c.start(out + at);
      });
      dec_.init();
      first_ = false;
      return;
    }
    coders_.each([&](auto& c, std::size_t at, std::size_t) { c.next(dec_, out + at); });
  }

 private:
  PointwiseItems coders_;
  ByteReader& in_;
  ArithmeticDecoder dec_;
  bool first_ = true;
};

class PointwiseChunkEncoder : public ChunkEncoder {
 public:
  PointwiseChunkEncoder(const std::vector<Item>& items, std::size_t record_length)
      : coders_(items), record_length_(record_length) {}
  void add(const unsigned char* record) override {
    if (enc_) return coders_.each([&](auto& c, std::size_t at, std::size_t) { c.encode(*enc_, record + at); });
    bytes_.insert(bytes_.end(), record, record + record_length_);
    coders_.each([&](auto& c, std::size_t at, std::size_t) { c.start(record + at); });
    enc_.emplace(bytes_);
  }
  std::vector<unsigned char> finish() override {
    if (enc_) enc_->done();
    return std::move(bytes_);
  }

 private:
  PointwiseItems coders_;
  std::size_t record_length_;
  std::vector<unsigned char> bytes_;
  std::optional<ArithmeticEncoder> enc_;
};

}  // namespace

void decode_pointwise_chunk(const std::vector<Item>& items, ByteReader& in, std::uint64_t n, unsigned char* record,
                            std::uint64_t& done, const RecordSink& on_record) {
  decode_points<PointwiseChunk>(items, in, n, record, done, on_record);
}

}  // namespace lodrefine::laz

namespace lodrefine::laz {

std::unique_ptr<ChunkEncoder> pointwise_chunk_encoder(const std::vector<Item>& items, std::size_t record_length) {
  return std::make_unique<PointwiseChunkEncoder>(items, record_length);
}

}  // namespace lodrefine::laz
