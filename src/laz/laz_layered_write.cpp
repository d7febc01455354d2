// LAZ compressor 3 encoder (chunked, layered: point formats 6-10): the inverse of
// laz_layered.cpp, on the same per-channel state (laz_layered.h). Per chunk: the first record
// raw, the point count, every layer's byte size, then the layers. A layer whose values never
// change in the chunk is left out (size 0), as LASzip's writer does: the decoder then keeps
// the last value, which is every point's.
#include <array>
#include <cstring>
#include <memory>
#include <optional>

#include "laz_layered.h"

namespace lodrefine::laz {
namespace {

// One layer being written: its own arithmetic stream, and whether a point changed its field.
struct OutLayer {
  std::vector<unsigned char> bytes;
  ArithmeticEncoder enc{bytes};
  bool changed = false;
};

unsigned merged_flags(unsigned char b) { return (b & 15u) | (b >> 6 & 1u) << 4 | (b >> 7 & 1u) << 5; }

// POINT14 v3 (LASzip's writer): a change mask in the XY layer, then every field in its layer.
class Point14Encoder {
 public:
  OutLayer& layer(int i) { return layers_[std::size_t(i)]; }
  void first(const unsigned char* item) {
    channel_ = (item[15] >> 4) & 3;
    context(channel_).start_from(item);
  }
  // Encodes one point; returns the other items' context (Point14Decoder::item_context: the
  // channel where it switches, else 0).
  int encode(const unsigned char* item) {
    Point14Context& prev = context(channel_);
    const unsigned prev_r = prev.last[14] & 15, prev_n = prev.last[14] >> 4;
    const unsigned stream = unsigned(prev_r == 1) | unsigned(prev_r >= prev_n) << 1 | unsigned(prev.gps_changed) << 2;
    const int channel = (item[15] >> 4) & 3;
    // The fields are compared with the channel's last point (a new channel's: the previous one).
    const unsigned char* last = ctx_[channel] && ctx_[channel]->used ? ctx_[channel]->last : prev.last;
    const unsigned n = item[14] >> 4, r = item[14] & 15, last_n = last[14] >> 4, last_r = last[14] & 15;
    const bool source_changed = get_u16(item + 20) != get_u16(last + 20);
    const bool gps_changed = get_u64(item + 22) != get_u64(last + 22);
    const bool angle_changed = get_u16(item + 18) != get_u16(last + 18);
    std::uint32_t changed = std::uint32_t(channel != channel_) << 6 | std::uint32_t(source_changed) << 5 |
                            std::uint32_t(gps_changed) << 4 | std::uint32_t(angle_changed) << 3 |
                            std::uint32_t(n != last_n) << 2;
    if (r != last_r) changed |= r == (last_r + 1) % 16 ? 1 : r == (last_r + 15) % 16 ? 2 : 3;
    ArithmeticEncoder& xy = layers_[kXY].enc;
    xy.symbol(prev.changed_values[stream], changed);
    if (changed & 64) {
      xy.symbol(prev.scanner_channel, std::uint32_t(channel - channel_ + 3) % 4);
      Point14Context& c = context(channel);
      if (!c.used) c.start_from(prev.last);
      channel_ = channel;
    }
    Point14Context& c = context(channel_);
    if (changed & 4) xy.symbol(c.nr[last_n], n);
    if ((changed & 3) == 3) {
      if (gps_changed) xy.symbol(c.rn[last_r], r);
      else xy.symbol(c.rn_gps_same, (r + 30 - last_r) % 16);
    }
    encode_xyz(c, item, n, r, gps_changed);
    encode_attributes(c, item, n, r, gps_changed);
    if (angle_changed) {
      layers_[kScanAngle].changed = true;
      c.ic_scan_angle.encode(layers_[kScanAngle].enc, std::int16_t(get_u16(c.last + 18)),
                             std::int16_t(get_u16(item + 18)), gps_changed);
    }
    if (source_changed) {
      layers_[kPointSource].changed = true;
      c.ic_point_source.encode(layers_[kPointSource].enc, get_u16(c.last + 20), get_u16(item + 20), 0);
    }
    if (gps_changed) {
      layers_[kGpsTime].changed = true;
      c.time.encode(layers_[kGpsTime].enc, get_u64(item + 22));
    }
    c.gps_changed = gps_changed;
    std::memcpy(c.last, item, 30);
    return changed & 64 ? channel_ : 0;
  }

 private:
  void encode_xyz(Point14Context& c, const unsigned char* item, unsigned n, unsigned r, bool gps_changed) {
    const unsigned ctx = unsigned(kReturnMap6[n][r]) << 1 | unsigned(gps_changed);
    const std::uint32_t single = n == 1;
    const auto dx = std::int32_t(get_u32(item) - get_u32(c.last));
    const auto dy = std::int32_t(get_u32(item + 4) - get_u32(c.last + 4));
    ArithmeticEncoder& xy = layers_[kXY].enc;
    c.ic_dx.encode(xy, c.x_median[ctx].get(), dx, single);
    c.x_median[ctx].add(dx);
    c.ic_dy.encode(xy, c.y_median[ctx].get(), dy, single | (std::min(c.ic_dx.k(), 20u) & ~1u));
    c.y_median[ctx].add(dy);
    const std::uint32_t k = std::min((c.ic_dx.k() + c.ic_dy.k()) / 2, 18u) & ~1u;
    const unsigned level = return_level8(n, r);
    const auto z = std::int32_t(get_u32(item + 8));
    layers_[kZ].changed |= z != std::int32_t(get_u32(c.last + 8));
    c.ic_z.encode(layers_[kZ].enc, c.last_z[level], z, single | k);
    c.last_z[level] = z;
  }
  // Class, flags, intensity and user data: coded for every point, each in its layer.
  void encode_attributes(Point14Context& c, const unsigned char* item, unsigned n, unsigned r, bool gps_changed) {
    const unsigned char* p = c.last;
    layers_[kClass].changed |= item[16] != p[16];
    layers_[kClass].enc.symbol(c.classification[unsigned(r == 1 && r >= n) | (p[16] & 0x1fu) << 1], item[16]);
    layers_[kFlags].changed |= merged_flags(item[15]) != merged_flags(p[15]);
    layers_[kFlags].enc.symbol(c.flags[merged_flags(p[15])], merged_flags(item[15]));
    const unsigned i = unsigned(gps_changed) | unsigned(r >= n) << 1 | unsigned(r == 1) << 2;
    const std::uint16_t intensity = get_u16(item + 12);
    layers_[kIntensity].changed |= intensity != get_u16(p + 12);
    c.ic_intensity.encode(layers_[kIntensity].enc, c.last_intensity[i], intensity, i >> 1);
    c.last_intensity[i] = intensity;
    layers_[kUserData].changed |= item[17] != p[17];
    layers_[kUserData].enc.symbol(c.user_data[p[17] / 4u], item[17]);
  }
  Point14Context& context(int channel) {
    if (!ctx_[channel]) ctx_[channel] = std::make_unique<Point14Context>();
    return *ctx_[channel];
  }

  std::array<std::unique_ptr<Point14Context>, 4> ctx_;
  std::array<OutLayer, kLayers> layers_;
  int channel_ = 0;
};

// RGB14 or RGBNIR14 (the inverse of Rgb14Decoder, with its channel bookkeeping).
class Rgb14Encoder {
 public:
  explicit Rgb14Encoder(bool nir) : nir_(nir) {}
  OutLayer& layer(int i) { return layers_[std::size_t(i)]; }
  bool nir() const { return nir_; }
  void first(const unsigned char* item, int channel) {
    state_.first(channel, {get_rgb(item), nir_ ? get_u16(item + 6) : 0u}, make());
  }
  void encode(const unsigned char* item, int channel) {
    Rgb14Last& last = state_.select(channel, make);
    const std::array<std::uint32_t, 3> rgb = get_rgb(item);
    layers_[0].changed |= encode_rgb(layers_[0].enc, state_.models().rgb, last.rgb, rgb) != 0;
    last.rgb = rgb;
    if (!nir_) return;
    std::uint32_t& kept = state_.current_last().nir;  // as the decoder keeps it
    const std::uint32_t nir = get_u16(item + 6);
    const std::uint32_t sym =
        std::uint32_t((nir & 0xff) != (last.nir & 0xff)) | std::uint32_t((nir >> 8) != (last.nir >> 8)) << 1;
    ArithmeticEncoder& enc = layers_[1].enc;
    NirModels& m = state_.models().nir;
    enc.symbol(m.byte_used, sym);
    if (sym & 1) enc.symbol(m.diff[0], (nir - last.nir) & 0xff);
    if (sym & 2) enc.symbol(m.diff[1], ((nir >> 8) - (last.nir >> 8)) & 0xff);
    layers_[1].changed |= nir != kept;
    kept = nir;
  }

 private:
  static std::unique_ptr<Rgb14Models> make() { return std::make_unique<Rgb14Models>(); }

  bool nir_;
  ChannelState<Rgb14Last, Rgb14Models> state_;
  std::array<OutLayer, 2> layers_;
};

// WAVEPACKET14: the waveform packet descriptor (the inverse of WavePacket14Decoder).
class WavePacket14Encoder : WavePacket14State {
 public:
  OutLayer& layer() { return layer_; }
  void first(const unsigned char* item, int channel) { start(item, channel); }
  void encode(const unsigned char* item, int channel) {
    Last& last = select(channel);
    encode_wavepacket(layer_.enc, state_.models(), last.data(), item);
    std::memcpy(last.data(), item, kWavePacketSize);
  }

 private:
  OutLayer layer_;
};

// BYTE14: each extra byte a difference to its last value, in its own layer.
class Byte14Encoder {
 public:
  explicit Byte14Encoder(std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) layers_.push_back(std::make_unique<OutLayer>());
  }
  std::size_t size() const { return layers_.size(); }
  OutLayer& layer(std::size_t i) { return *layers_[i]; }
  void first(const unsigned char* item, int channel) {
    state_.first(channel, std::vector<unsigned char>(item, item + size()), make(size()));
  }
  void encode(const unsigned char* item, int channel) {
    const std::size_t n = size();
    std::vector<unsigned char>& last = state_.select(channel, [n] { return make(n); });
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t sym = std::uint32_t(item[i] - last[i]) & 0xff;
      layers_[i]->changed |= sym != 0;
      layers_[i]->enc.symbol(state_.models()[i], sym);
      last[i] = item[i];
    }
  }

 private:
  using Models = std::vector<SymbolModel>;
  static std::unique_ptr<Models> make(std::size_t n) { return std::make_unique<Models>(n, SymbolModel(256)); }

  std::vector<std::unique_ptr<OutLayer>> layers_;
  ChannelState<std::vector<unsigned char>, Models> state_;
};

class LayeredChunkEncoder : public ChunkEncoder {
 public:
  LayeredChunkEncoder(const std::vector<Item>& items, std::size_t record_length)
      : record_length_(record_length), items_(items) {}
  void add(const unsigned char* record) override {
    ++count_;
    if (count_ == 1) {
      first_.assign(record, record + record_length_);
      point_.first(record);
      const int ch = (record[15] >> 4) & 3;
      items_.each([&](auto& item, std::size_t at) { item.first(record + at, ch); });
      return;
    }
    const int ch = point_.encode(record);
    items_.each([&](auto& item, std::size_t at) { item.encode(record + at, ch); });
  }
  // The first record, the count, the layer sizes, the layers (the XY layer always: it carries
  // every point's change mask).
  std::vector<unsigned char> finish() override {
    std::vector<OutLayer*> layers;
    for (int i = 0; i < kLayers; ++i) layers.push_back(&point_.layer(i));
    if (auto& rgb = items_.rgb) {
      layers.push_back(&rgb->layer(0));
      if (rgb->nir()) layers.push_back(&rgb->layer(1));
    }
    if (items_.wave) layers.push_back(&items_.wave->layer());
    if (items_.bytes)
      for (std::size_t i = 0; i < items_.bytes->size(); ++i) layers.push_back(&items_.bytes->layer(i));
    point_.layer(kXY).changed = true;
    if (items_.wave) items_.wave->layer().changed = true;  // always written: the decoder then never guesses
    std::vector<unsigned char> out = std::move(first_);
    append_u32(out, count_);
    for (OutLayer* l : layers) {
      if (l->changed) l->enc.done();
      append_u32(out, l->changed ? std::uint32_t(l->bytes.size()) : 0u);
    }
    for (OutLayer* l : layers)
      if (l->changed) out.insert(out.end(), l->bytes.begin(), l->bytes.end());
    return out;
  }

 private:
  static void append_u32(std::vector<unsigned char>& out, std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back((unsigned char)(v >> (8 * i)));
  }

  std::size_t record_length_;
  std::uint32_t count_ = 0;
  std::vector<unsigned char> first_;
  Point14Encoder point_;
  LayeredItems<Rgb14Encoder, WavePacket14Encoder, Byte14Encoder> items_;
};

}  // namespace

std::unique_ptr<ChunkEncoder> layered_chunk_encoder(const std::vector<Item>& items, std::size_t record_length) {
  return std::make_unique<LayeredChunkEncoder>(items, record_length);
}

}  // namespace lodrefine::laz
