// J1939 network management and diagnostics without a bus: the NAME, Address Claimed, Cannot
// Claim and Request frames, the claim procedure (AddressClaimer) and DM1.
#include <gtest/gtest.h>

#include "allocation_counter.hpp"
#include "craneassist/can/address_claim.hpp"
#include "craneassist/can/dm1.hpp"

using namespace craneassist::can;
using namespace craneassist::can::j1939;

namespace {

CanFrame frame(std::uint32_t id, std::initializer_list<std::uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  f.extended = true;
  f.dlc = static_cast<std::uint8_t>(bytes.size());
  std::size_t i = 0;
  for (auto b : bytes) f.data[i++] = b;
  return f;
}

constexpr std::uint64_t kOurs = 0x30C8820000C1A0FFull;  // arbitrary, bit 63 clear

}  // namespace

TEST(J1939Name, PacksTheFieldsAtTheirBits) {
  Name n;
  n.identity_number = 0x1ABCDE;
  n.manufacturer_code = 0x5A5;
  n.ecu_instance = 5;
  n.function_instance = 0x13;
  n.function = 0x82;
  n.vehicle_system = 0x55;
  n.vehicle_system_instance = 0xA;
  n.industry_group = 3;
  n.arbitrary_address_capable = true;
  const std::uint64_t v = pack_name(n);
  EXPECT_EQ(v & 0x1FFFFF, 0x1ABCDEu);
  EXPECT_EQ((v >> 21) & 0x7FF, 0x5A5u);
  EXPECT_EQ((v >> 32) & 0x7, 5u);
  EXPECT_EQ((v >> 35) & 0x1F, 0x13u);
  EXPECT_EQ((v >> 40) & 0xFF, 0x82u);
  EXPECT_EQ((v >> 48) & 1, 0u);  // reserved
  EXPECT_EQ((v >> 49) & 0x7F, 0x55u);
  EXPECT_EQ((v >> 56) & 0xF, 0xAu);
  EXPECT_EQ((v >> 60) & 0x7, 3u);
  EXPECT_EQ(v >> 63, 1u);
  const Name back = unpack_name(v);
  EXPECT_EQ(back.identity_number, n.identity_number);
  EXPECT_EQ(back.manufacturer_code, n.manufacturer_code);
  EXPECT_EQ(back.function, n.function);
  EXPECT_EQ(back.vehicle_system_instance, n.vehicle_system_instance);
  EXPECT_TRUE(back.arbitrary_address_capable);
  EXPECT_EQ(pack_name(back), v);
}

TEST(J1939Network, AddressClaimedCannotClaimAndRequestFrames) {
  CanFrame f;
  encode_address_claimed(0x0123456789ABCDEFull, 0x80, f);
  EXPECT_EQ(f.id, 0x18EEFF80u);  // priority 6, PGN 0xEE00, to global, from 0x80
  EXPECT_TRUE(f.extended);
  ASSERT_EQ(f.dlc, 8);
  EXPECT_EQ(f.data[0], 0xEF);  // least significant byte first
  EXPECT_EQ(f.data[7], 0x01);
  std::uint64_t name = 0;
  std::uint8_t sa = 0;
  ASSERT_TRUE(decode_address_claimed(f, name, sa));
  EXPECT_EQ(name, 0x0123456789ABCDEFull);
  EXPECT_EQ(sa, 0x80);
  encode_address_claimed(0x0123456789ABCDEFull, kNullAddress, f);
  EXPECT_EQ(f.id, 0x18EEFFFEu);  // Cannot Claim Address

  encode_request(kPgnAddressClaimed, 0x21, kGlobalAddress, f);
  EXPECT_EQ(f.id, 0x18EAFF21u);
  ASSERT_EQ(f.dlc, 3);
  EXPECT_EQ(f.data[0], 0x00);
  EXPECT_EQ(f.data[1], 0xEE);
  EXPECT_EQ(f.data[2], 0x00);
  std::uint32_t pgn_value = 0;
  std::uint8_t dest = 0;
  ASSERT_TRUE(decode_request(f, pgn_value, dest));
  EXPECT_EQ(pgn_value, kPgnAddressClaimed);
  EXPECT_EQ(dest, kGlobalAddress);
  // Padded to 8 bytes, addressed to 0x80.
  ASSERT_TRUE(decode_request(frame(0x18EA8021, {0, 0xEE, 0, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}),
                             pgn_value, dest));
  EXPECT_EQ(dest, 0x80);
  // Too short, an 11-bit id, another PGN: not these messages.
  EXPECT_FALSE(decode_request(frame(0x18EAFF21, {0, 0xEE}), pgn_value, dest));
  EXPECT_FALSE(decode_address_claimed(frame(0x18EEFF80, {1, 2, 3}), name, sa));
  CanFrame std_id = frame(0x0EE, {1, 2, 3, 4, 5, 6, 7, 8});
  std_id.extended = false;
  EXPECT_FALSE(decode_address_claimed(std_id, name, sa));
  EXPECT_FALSE(decode_address_claimed(frame(0x18EFFF80, {1, 2, 3, 4, 5, 6, 7, 8}), name, sa));
}

TEST(AddressClaimer, ClaimsAfterTheTimeoutWithoutContention) {
  AddressClaimer c(0x80, kOurs);
  CanFrame out;
  EXPECT_EQ(c.state(), ClaimState::kIdle);
  c.start(1000, out);
  EXPECT_EQ(out.id, 0x18EEFF80u);
  EXPECT_EQ(c.state(), ClaimState::kClaiming);
  EXPECT_EQ(c.poll(1000 + 249000, out), AddressClaimer::Action::kNone);
  EXPECT_EQ(c.state(), ClaimState::kClaiming);
  c.poll(1000 + 250000, out);
  EXPECT_EQ(c.state(), ClaimState::kClaimed);
  // Claims of other addresses and Cannot Claim messages are not ours.
  CanFrame other;
  encode_address_claimed(1, 0x81, other);
  EXPECT_EQ(c.on_frame(other, 300000, out), AddressClaimer::Action::kNone);
  encode_address_claimed(1, kNullAddress, other);
  EXPECT_EQ(c.on_frame(other, 300000, out), AddressClaimer::Action::kNone);
  EXPECT_EQ(c.state(), ClaimState::kClaimed);
}

TEST(AddressClaimer, ContentionLowerNameWinsEqualNameGivesWay) {
  CanFrame out, theirs;
  {
    AddressClaimer c(0x80, kOurs);
    c.start(0, out);
    encode_address_claimed(kOurs + 1, 0x80, theirs);  // lower priority
    EXPECT_EQ(c.on_frame(theirs, 100000, out), AddressClaimer::Action::kSend);
    EXPECT_EQ(out.id, 0x18EEFF80u);  // our claim again
    EXPECT_EQ(out.data[0], kOurs & 0xFF);
    // The wait starts again from the repeated claim.
    c.poll(300000, out);
    EXPECT_EQ(c.state(), ClaimState::kClaiming);
    c.poll(350000, out);
    EXPECT_EQ(c.state(), ClaimState::kClaimed);
  }
  for (const std::uint64_t rival : {kOurs - 1, kOurs}) {
    AddressClaimer c(0x80, kOurs);
    c.start(0, out);
    encode_address_claimed(rival, 0x80, theirs);
    EXPECT_EQ(c.on_frame(theirs, 100000, out), AddressClaimer::Action::kLost);
    EXPECT_EQ(out.id, 0x18EEFFFEu);  // Cannot Claim Address, with our NAME
    EXPECT_EQ(out.data[0], kOurs & 0xFF);
    EXPECT_EQ(c.state(), ClaimState::kLost);
    EXPECT_EQ(c.rival_name(), rival);
    // Lost stays lost: the timeout does not make the address ours.
    c.poll(10000000, out);
    EXPECT_EQ(c.state(), ClaimState::kLost);
  }
  // Lost while claimed (during operation).
  AddressClaimer c(0x80, kOurs);
  c.start(0, out);
  c.poll(250000, out);
  encode_address_claimed(0x10, 0x80, theirs);
  EXPECT_EQ(c.on_frame(theirs, 900000, out), AddressClaimer::Action::kLost);
  EXPECT_EQ(c.state(), ClaimState::kLost);
}

TEST(AddressClaimer, AnswersRequestsForAddressClaimed) {
  AddressClaimer c(0x80, kOurs);
  CanFrame out, req;
  encode_request(kPgnAddressClaimed, 0x21, kGlobalAddress, req);
  EXPECT_EQ(c.on_frame(req, 0, out), AddressClaimer::Action::kNone);  // not claiming yet
  c.start(0, out);
  for (std::uint8_t dest : {kGlobalAddress, std::uint8_t{0x80}}) {
    encode_request(kPgnAddressClaimed, 0x21, dest, req);
    out = CanFrame{};
    EXPECT_EQ(c.on_frame(req, 1000, out), AddressClaimer::Action::kSend);
    EXPECT_EQ(out.id, 0x18EEFF80u);
  }
  encode_request(kPgnAddressClaimed, 0x21, 0x81, req);  // to another node
  EXPECT_EQ(c.on_frame(req, 1000, out), AddressClaimer::Action::kNone);
  encode_request(0xFECA, 0x21, kGlobalAddress, req);  // a request for another PGN
  EXPECT_EQ(c.on_frame(req, 1000, out), AddressClaimer::Action::kNone);

  // Lost: a global request is answered with Cannot Claim after 0..153 ms, once.
  CanFrame theirs;
  encode_address_claimed(1, 0x80, theirs);
  c.on_frame(theirs, 2000, out);
  ASSERT_EQ(c.state(), ClaimState::kLost);
  encode_request(kPgnAddressClaimed, 0x21, kGlobalAddress, req);
  EXPECT_EQ(c.on_frame(req, 10000, out), AddressClaimer::Action::kNone);
  int answers = 0;
  std::int64_t answered_at = -1;
  for (std::int64_t t = 10000; t <= 10000 + 160000; t += 1000) {
    out = CanFrame{};
    if (c.poll(t, out) == AddressClaimer::Action::kSend) {
      ++answers;
      answered_at = t;
      EXPECT_EQ(out.id, 0x18EEFFFEu);
    }
  }
  EXPECT_EQ(answers, 1);
  EXPECT_LE(answered_at - 10000, 154000);
  // A request to the lost address is not ours to answer.
  encode_request(kPgnAddressClaimed, 0x21, 0x80, req);
  c.on_frame(req, 200000, out);
  EXPECT_EQ(c.poll(400000, out), AddressClaimer::Action::kNone);
}

TEST(Dm1, DecodesTheLampsAndTheFirstDtc) {
  // Red stop lamp on, amber off, SPN 1234 (0x4D2) FMI 5, occurrence 1.
  const CanFrame f = frame(0x18FECA20, {0x10, 0xFF, 0xD2, 0x04, 0x05, 0x01, 0xFF, 0xFF});
  Dm1 d;
  std::uint8_t sa = 0;
  ASSERT_EQ(decode_dm1(f, d, sa), Dm1Status::kOk);
  EXPECT_EQ(sa, 0x20);
  EXPECT_EQ(d.red_stop, Lamp::kOn);
  EXPECT_EQ(d.mil, Lamp::kOff);
  EXPECT_EQ(d.amber_warning, Lamp::kOff);
  EXPECT_EQ(d.spn, 1234u);
  EXPECT_EQ(d.fmi, 5);
  EXPECT_EQ(d.occurrence_count, 1);
  EXPECT_TRUE(dm1_requires_stop(d));
  CanFrame back;
  encode_dm1(d, 0x20, back);
  EXPECT_TRUE(same_frame(back, f));

  // The 19-bit SPN's top bits sit in byte 5 bits 8-6: SPN 520192 (0x7F000) FMI 31.
  ASSERT_EQ(decode_dm1(frame(0x18FECA20, {0x04, 0xFF, 0x00, 0xF0, 0xFF, 0x83, 0xFF, 0xFF}), d, sa),
            Dm1Status::kOk);
  EXPECT_EQ(d.spn, 0x7F000u);
  EXPECT_EQ(d.fmi, 31);
  EXPECT_EQ(d.amber_warning, Lamp::kOn);
  EXPECT_TRUE(d.conversion_method);
  EXPECT_EQ(d.occurrence_count, 3);
  EXPECT_TRUE(dm1_requires_stop(d));  // any active DTC

  // No active DTC: lamps off, SPN 0 (or all ones); a lamp other than red stop alone: no stop.
  ASSERT_EQ(decode_dm1(frame(0x18FECA20, {0x00, 0xFF, 0, 0, 0, 0, 0xFF, 0xFF}), d, sa),
            Dm1Status::kOk);
  EXPECT_FALSE(dm1_requires_stop(d));
  ASSERT_EQ(decode_dm1(frame(0x18FECA20, {0x0C, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF}), d, sa),
            Dm1Status::kOk);
  EXPECT_EQ(d.spn, kSpnNotAvailable);
  EXPECT_FALSE(dm1_requires_stop(d));  // amber lamp "not available", no DTC
  ASSERT_EQ(decode_dm1(frame(0x18FECA20, {0x10, 0xFF, 0, 0, 0, 0, 0xFF, 0xFF}), d, sa),
            Dm1Status::kOk);
  EXPECT_TRUE(dm1_requires_stop(d));  // red stop lamp without a DTC

  EXPECT_EQ(decode_dm1(frame(0x18FECA20, {0x10, 0xFF, 0xD2}), d, sa), Dm1Status::kTooShort);
  EXPECT_EQ(decode_dm1(frame(0x18FECB20, {0x10, 0xFF, 0xD2, 4, 5, 1, 0xFF, 0xFF}), d, sa),
            Dm1Status::kNotDm1);
}

TEST(Dm1, MultiPacketDm1IsRecognisedByItsAnnouncementNeverMisread) {
  // TP.CM BAM from 0x20: 14 bytes (3 DTCs) in 2 packets of PGN 0x00FECA.
  const CanFrame bam = frame(0x1CECFF20, {32, 14, 0, 2, 0xFF, 0xCA, 0xFE, 0x00});
  std::uint8_t sa = 0;
  std::uint16_t size = 0;
  ASSERT_TRUE(decode_dm1_announcement(bam, sa, size));
  EXPECT_EQ(sa, 0x20);
  EXPECT_EQ(size, 14);
  // A BAM of another PGN, an RTS (control 16): not a DM1 announcement.
  EXPECT_FALSE(
      decode_dm1_announcement(frame(0x1CECFF20, {32, 14, 0, 2, 0xFF, 0xCB, 0xFE, 0}), sa, size));
  EXPECT_FALSE(
      decode_dm1_announcement(frame(0x1CEC8020, {16, 14, 0, 2, 0xFF, 0xCA, 0xFE, 0}), sa, size));
  // The TP.DT packets (PGN 0xEB00) are not a DM1.
  Dm1 d;
  EXPECT_EQ(decode_dm1(frame(0x1CEBFF20, {1, 0x10, 0xFF, 0xD2, 4, 5, 1, 0xD3}), d, sa),
            Dm1Status::kNotDm1);
}

TEST(J1939Network, CodecsAndTheClaimerDoNotAllocate) {
  AddressClaimer c(0x80, kOurs);
  CanFrame out, theirs, req;
  encode_address_claimed(kOurs + 1, 0x80, theirs);
  encode_request(kPgnAddressClaimed, 0x21, kGlobalAddress, req);
  const CanFrame dm1 = frame(0x18FECA20, {0x10, 0xFF, 0xD2, 0x04, 0x05, 0x01, 0xFF, 0xFF});
  const long before = craneassist::test::heap_allocations();
  c.start(0, out);
  c.on_frame(theirs, 1000, out);
  c.on_frame(req, 2000, out);
  c.poll(400000, out);
  Dm1 d;
  std::uint8_t sa = 0;
  decode_dm1(dm1, d, sa);
  EXPECT_EQ(craneassist::test::heap_allocations(), before);
}
