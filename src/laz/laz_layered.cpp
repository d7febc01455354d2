// LAZ compressor 3 (chunked, layered: LASzip for LAS 1.4; point formats 6-8): per chunk the
// first point raw, the chunk's point count, the byte size of every layer, then the layers, each
// its own arithmetic stream. Point fields keep one context per scanner channel. The version-3
// item decoders of POINT14, RGB14, RGBNIR14 and BYTE14, and one chunk's decoding (laz_items.h).
#include <algorithm>
#include <array>
#include <cstring>
#include <functional>
#include <memory>
#include <optional>

#include "laz_layered.h"

namespace lodrefine::laz {
namespace {

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

class Point14Decoder {
 public:
  // The context the other items of this point use (LASzip's reader, laz-perf): the channel
  // on the chunk's first point and where it switches, 0 on every other point.
  int item_context() const { return item_context_; }
  void first(ByteReader& in, unsigned char* out) {
    in.bytes(out, 30);
    channel_ = item_context_ = (out[15] >> 4) & 3;
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
    item_context_ = changed & 64 ? channel : 0;
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
      p[16] =
          (unsigned char)layers_[kClass]->symbol(c.classification[unsigned(r == 1 && r >= n) | (p[16] & 0x1f) << 1]);
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
      put_u16(p + 18,
              std::uint16_t(c.ic_scan_angle.decode(*layers_[kScanAngle], std::int16_t(get_u16(p + 18)), gps_changed)));
    if (layers_[kUserData].present()) p[17] = (unsigned char)layers_[kUserData]->symbol(c.user_data[p[17] / 4]);
    if (changed & 32)
      put_u16(p + 20, std::uint16_t(c.ic_point_source.decode(*layers_[kPointSource], get_u16(p + 20), 0)));
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
  int channel_ = 0, item_context_ = 0;
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
  bool nir() const { return nir_; }
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
  using Last = Rgb14Last;
  using Models = Rgb14Models;
  static std::unique_ptr<Models> make() { return std::make_unique<Models>(); }

  bool nir_;
  ChannelState<Last, Models> state_;
  std::array<Layer, 2> layers_;
};

// WAVEPACKET14 (formats 9 and 10): the waveform packet descriptor in its own layer.
class WavePacket14Decoder : WavePacket14State {
 public:
  void first(ByteReader& in, unsigned char* out, int channel) {
    in.bytes(out, kWavePacketSize);
    start(out, channel);
  }
  Layer& layer() { return layer_; }
  void next(unsigned char* out, int channel) {
    Last& last = select(channel);
    if (layer_.present()) decode_wavepacket(*layer_, state_.models(), last.data(), out);
    else std::memcpy(out, last.data(), kWavePacketSize);
    std::memcpy(last.data(), out, kWavePacketSize);
  }

 private:
  Layer layer_;
};

// BYTE14: each extra byte its own layer, a difference to its last value. A byte's model is made
// when its layer first codes a change in a channel: a record may carry 65,535 extra bytes in four
// channels, 2 KB a model, and a chunk of a few hundred KB may switch through all four. The models
// of one chunk are bounded by kMaxByteModels.
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
      if (layers_[i].present()) last[i] = (unsigned char)(last[i] + layers_[i]->symbol(model(i)));
      out[i] = last[i];
    }
  }

 private:
  // 16,384 models, 32 MB: 4,096 extra bytes changing in every channel.
  static constexpr std::size_t kMaxByteModels = 16384;
  using Models = std::vector<std::unique_ptr<SymbolModel>>;
  static std::unique_ptr<Models> make(std::size_t n) { return std::make_unique<Models>(n); }
  SymbolModel& model(std::size_t i) {
    std::unique_ptr<SymbolModel>& m = state_.models()[i];
    if (!m) {
      if (++made_ > kMaxByteModels) throw Corrupt{"more than 16384 extra-byte models in one chunk"};
      m = std::make_unique<SymbolModel>(256);
    }
    return *m;
  }

  std::vector<Layer> layers_;
  ChannelState<std::vector<unsigned char>, Models> state_;
  std::size_t made_ = 0;
};

// One chunk of a layered (compressor 3) file.
class LayeredChunk {
 public:
  LayeredChunk(const std::vector<Item>& items, ByteReader& in) : in_(in), items_(items) {}
  void decode(unsigned char* out) {
    if (first_) return decode_first(out);
    point_.next(out);
    const int ch = point_.item_context();
    items_.each([&](auto& item, std::size_t at) { item.next(out + at, ch); });
  }

 private:
  // The raw first point, then the count, the layer sizes and the layers themselves.
  void decode_first(unsigned char* out) {
    first_ = false;
    point_.first(in_, out);
    const int ch = point_.item_context();
    items_.each([&](auto& item, std::size_t at) { item.first(in_, out + at, ch); });
    unsigned char b[4];
    in_.bytes(b, 4);  // the chunk's point count: the chunk table's is used
    std::vector<std::pair<Layer*, std::uint32_t>> sizes;
    for (Layer& l : point_.layers()) sizes.push_back({&l, read_u32()});
    if (auto& rgb = items_.rgb) {
      sizes.push_back({&rgb->layers()[0], read_u32()});
      if (rgb->nir()) sizes.push_back({&rgb->layers()[1], read_u32()});
    }
    if (items_.wave) sizes.push_back({&items_.wave->layer(), read_u32()});
    if (items_.bytes)
      for (Layer& l : items_.bytes->layers()) sizes.push_back({&l, read_u32()});
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
  LayeredItems<Rgb14Decoder, WavePacket14Decoder, Byte14Decoder> items_;
};

}  // namespace

void decode_layered_chunk(const std::vector<Item>& items, ByteReader& in, std::uint64_t n, unsigned char* record,
                          std::uint64_t& done, const RecordSink& on_record) {
  decode_points<LayeredChunk>(items, in, n, record, done, on_record);
}

}  // namespace lodrefine::laz
