// Internal to the laz library's LAZ codec: the state LASzip's layered compressor (compressor 3,
// point formats 6-8) keeps per scanner channel, shared by the decoder (laz_layered.cpp) and the
// encoder (laz_layered_write.cpp): context tables, POINT14's per-channel models, and the
// channel bookkeeping of RGB14, RGBNIR14 and BYTE14.
#pragma once
#include <algorithm>
#include <array>
#include <cstring>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "laz_items.h"

namespace lodrefine::laz {

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
inline unsigned return_level8(unsigned n, unsigned r) {
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
  IntegerCoder ic_dx{32, 2}, ic_dy{32, 22}, ic_z{32, 20}, ic_intensity{16, 4}, ic_scan_angle{16, 2},
      ic_point_source{16, 1};
  GpsTimeCoder time{true};

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

// RGB14 / RGBNIR14 and BYTE14 keep their models and last values per scanner channel too. As
// LASzip's v3 readers do (and laz-perf): a channel's first point continues from the channel
// before it; after a switch back to a channel already seen in the chunk, the prediction still
// comes from (and updates) the previous channel's last value, with the new channel's models.
// The channel given is POINT14's item context (0 except on a switch), not the point's channel.
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

// The items after POINT14 of a layered record (colour, waveform packet, extra bytes), as
// decoders or encoders of either direction, each with its offset in the record.
template <class Rgb, class Wave, class Bytes>
struct LayeredItems {
  explicit LayeredItems(const std::vector<Item>& items) {
    std::size_t at = 30;
    for (const Item& it : items) {
      if (it.type == kRgb14 || it.type == kRgbNir14) rgb.emplace(it.type == kRgbNir14), rgb_at = at;
      else if (it.type == kWavePacket14) wave.emplace(), wave_at = at;
      else if (it.type == kByte14) bytes.emplace(it.size), bytes_at = at;
      if (it.type != kPoint14) at += it.size;
    }
  }
  // Calls f(item, its offset in the record) for each present item, in record order.
  template <class F>
  void each(F&& f) {
    if (rgb) f(*rgb, rgb_at);
    if (wave) f(*wave, wave_at);
    if (bytes) f(*bytes, bytes_at);
  }

  std::optional<Rgb> rgb;
  std::optional<Wave> wave;
  std::optional<Bytes> bytes;
  std::size_t rgb_at = 0, wave_at = 0, bytes_at = 0;
};

// WAVEPACKET14's per-channel state (the last packet, the models), for its decoder and encoder.
class WavePacket14State {
 protected:
  using Last = std::array<unsigned char, kWavePacketSize>;
  static std::unique_ptr<WavePacketModels> make() { return std::make_unique<WavePacketModels>(); }
  void start(const unsigned char* first, int channel) {
    Last last;
    std::memcpy(last.data(), first, kWavePacketSize);
    state_.first(channel, last, make());
  }
  // The last packet to predict from (ChannelState::select); its models are state_.models().
  Last& select(int channel) { return state_.select(channel, make); }

  ChannelState<Last, WavePacketModels> state_;
};

struct Rgb14Last {
  std::array<std::uint32_t, 3> rgb{};
  std::uint32_t nir = 0;
};
struct Rgb14Models {
  RgbModels rgb;
  NirModels nir;
};

}  // namespace lodrefine::laz
