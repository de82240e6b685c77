// DBC-style signals (can::SignalSpec, can/signal_map.hpp): any spec (valid or not) on any frame.
// validate() decides; an invalid spec is refused by every function, never read; a valid one
// decodes any frame that covers it, and within its raw range a decoded value encodes back to the
// same bits.
#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "craneassist/can/signal_map.hpp"
#include "fuzz_check.hpp"

namespace can = craneassist::can;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  can::SignalSpec spec;
  spec.extended = in.ConsumeBool();
  spec.id = in.ConsumeIntegralInRange<std::uint32_t>(0, 0x3FFFFFFF);
  spec.start_bit = in.ConsumeIntegralInRange<std::uint16_t>(0, 70);
  spec.length = in.ConsumeIntegralInRange<std::uint16_t>(0, 70);
  spec.byte_order = in.ConsumeBool() ? can::ByteOrder::kBigEndian : can::ByteOrder::kLittleEndian;
  spec.is_signed = in.ConsumeBool();
  const bool plain = in.ConsumeBool();  // a scale and offset of everyday size, or any double
  if (plain) {
    spec.scale = in.ConsumeFloatingPointInRange(1e-3, 1e3) * (in.ConsumeBool() ? -1.0 : 1.0);
    spec.offset = in.ConsumeFloatingPointInRange(-1e4, 1e4);
  } else {
    spec.scale = in.ConsumeFloatingPoint<double>();
    spec.offset = in.ConsumeFloatingPoint<double>();
  }
  if (in.ConsumeBool()) spec.minimum = in.ConsumeFloatingPoint<double>();
  if (in.ConsumeBool()) spec.maximum = in.ConsumeFloatingPoint<double>();

  can::CanFrame frame;
  frame.id = spec.id;
  frame.extended = spec.extended;
  if (in.ConsumeBool()) frame.id = in.ConsumeIntegral<std::uint32_t>();
  frame.dlc = in.ConsumeIntegralInRange<std::uint8_t>(0, 8);
  for (auto& byte : frame.data) byte = in.ConsumeIntegral<std::uint8_t>();
  const double value_to_encode = in.ConsumeFloatingPoint<double>();

  const can::SpecError error = can::validate(spec);
  (void)can::to_string(error);
  const std::uint8_t dlc = can::required_dlc(spec);
  FUZZ_CHECK((error == can::SpecError::kNone) == (dlc >= 1 && dlc <= 8),
             "required_dlc is 1..8 exactly for a valid spec");

  std::uint64_t raw = 0;
  const bool extracted = can::extract_raw(spec, frame, raw);
  FUZZ_CHECK(!extracted || error == can::SpecError::kNone, "an invalid spec is never read");
  if (extracted && spec.length < 64) FUZZ_CHECK(raw >> spec.length == 0, "raw fits the length");

  double value = 0.0;
  const can::SignalStatus status = can::decode(spec, frame, value);
  (void)can::to_string(status);
  if (error != can::SpecError::kNone) {
    FUZZ_CHECK(status == can::SignalStatus::kInvalidSpec, "an invalid spec is refused");
  }
  if (status == can::SignalStatus::kOk || status == can::SignalStatus::kOutOfRange) {
    FUZZ_CHECK(extracted, "decode reads what extract_raw reads");
    FUZZ_CHECK(!std::isnan(value), "a decoded value is a number");
  }

  // Encode into a copy: the other bits stay; a decoded in-range value of an everyday spec
  // round-trips to the same raw bits.
  can::CanFrame written = frame;
  const can::SignalStatus encoded = can::encode(spec, value_to_encode, written);
  (void)can::to_string(encoded);
  if (error != can::SpecError::kNone) {
    FUZZ_CHECK(encoded == can::SignalStatus::kInvalidSpec, "an invalid spec writes nothing");
  }
  if (plain && status == can::SignalStatus::kOk && spec.length <= 32) {
    can::CanFrame again = frame;
    FUZZ_CHECK(can::encode(spec, value, again) == can::SignalStatus::kOk, "re-encodes");
    std::uint64_t raw_again = 0;
    FUZZ_CHECK(can::extract_raw(spec, again, raw_again) && raw_again == raw,
               "decode -> encode keeps the raw bits");
    FUZZ_CHECK(again.data == frame.data, "and every other bit of the frame");
  }
  if (error == can::SpecError::kNone && spec.length < 64) {
    (void)can::sign_extend(raw, spec.length);
  }
  return 0;
}
