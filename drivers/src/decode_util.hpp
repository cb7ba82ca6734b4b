#pragma once
// Private to drivers/: the common part of the devices' decoders (registry.hpp, Decoder): a
// codec fed chunk by chunk, its errors as decoded items, its frames mapped to readings by the
// device.
#include <span>
#include <utility>
#include <vector>

#include "cal/drivers/registry.hpp"

namespace cal::drivers::detail {

inline void add_errors(std::span<const codec::CodecError> errors, std::vector<DecodedItem>& out) {
  for (const auto& e : errors)
    out.push_back({.kind = DecodedItem::Kind::error,
                   .offset = e.offset,
                   .error_kind = std::string(codec::to_string(e.kind)),
                   .text = e.description});
}

inline DecodedItem reading_item(std::uint64_t offset, std::uint8_t channel, Quantity q,
                                double value, ReadingStatus status = ReadingStatus::ok) {
  return {.offset = offset, .channel = channel, .quantity = q, .status = status, .value = value};
}

// OnFrame: void(const Codec::Frame&, std::uint64_t chunk_offset, std::vector<DecodedItem>&).
template <class Codec, class OnFrame>
class CodecDecoder final : public Decoder {
 public:
  CodecDecoder(Codec codec, OnFrame on_frame)
      : codec_(std::move(codec)), on_frame_(std::move(on_frame)) {}
  void feed(std::span<const std::byte> bytes, std::vector<DecodedItem>& out) override {
    const std::uint64_t offset = codec_.stats().bytes;
    frames_.clear();
    errors_.clear();
    codec_.feed(bytes, frames_, errors_);
    add_errors(errors_, out);
    for (const auto& f : frames_) on_frame_(f, offset, out);
  }
  const codec::CodecStats& stats() const override { return codec_.stats(); }
  Codec& codec() { return codec_; }

 private:
  Codec codec_;
  OnFrame on_frame_;
  std::vector<typename Codec::Frame> frames_;
  std::vector<codec::CodecError> errors_;
};

// A decoder that reads its input as text lines (transcripts, hex dumps) and hands each line,
// with its stream offset, to on_line; an overlong line is reported as an error.
class LineDecoder : public Decoder {
 public:
  explicit LineDecoder(std::string_view what) : what_(what) {}
  void feed(std::span<const std::byte> bytes, std::vector<DecodedItem>& out) override {
    lines_.feed(
        bytes, [&](std::string_view line, std::uint64_t offset) { on_line(line, offset, out); },
        [&](std::uint64_t offset) {
          out.push_back({.kind = DecodedItem::Kind::error,
                         .offset = offset,
                         .error_kind = "overlong_line",
                         .text = std::string(what_) + ": line longer than the buffer"});
        });
  }

 protected:
  virtual void on_line(std::string_view line, std::uint64_t offset,
                       std::vector<DecodedItem>& out) = 0;
  // The codec's errors, placed at the line they came from.
  static void add_errors_at(std::uint64_t offset, std::vector<codec::CodecError> errors,
                            std::vector<DecodedItem>& out) {
    for (auto& e : errors) e.offset = offset;
    add_errors(errors, out);
  }

 private:
  std::string_view what_;
  codec::LineSplitter lines_;
};

template <class Codec, class OnFrame>
std::unique_ptr<Decoder> make_codec_decoder(Codec codec, OnFrame on_frame) {
  return std::make_unique<CodecDecoder<Codec, OnFrame>>(std::move(codec), std::move(on_frame));
}

}  // namespace cal::drivers::detail
