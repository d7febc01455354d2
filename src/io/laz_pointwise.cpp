// LAZ compressor 2 (chunked, pointwise; point formats 0-3): the version-2 item decoders of
// POINT10, RGB12 and BYTE, and one chunk's decoding (laz_items.h).
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
    for (std::size_t i = 0; i < last_.size(); ++i)
      out[i] = last_[i] = (unsigned char)(last_[i] + dec.symbol(models_[i]));
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

}  // namespace

void decode_pointwise_chunk(const std::vector<Item>& items, ByteReader& in, std::uint64_t n, unsigned char* record,
                            std::uint64_t& done, const RecordSink& on_record) {
  decode_points<PointwiseChunk>(items, in, n, record, done, on_record);
}

}  // namespace lodrefine::laz
