#include "craneassist/can/dbc.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "craneassist/can/address_claim.hpp"
#include "craneassist/can/dm1.hpp"
#include "craneassist/can/iso11783_valve.hpp"
#include "craneassist/can/j1939.hpp"
#include "craneassist/config/config_error.hpp"
#include "craneassist/files/text_file.hpp"

namespace craneassist::can {
namespace {

using config::ConfigError;

// DBC marks a 29-bit identifier with bit 31 of the message id.
constexpr std::uint32_t kDbcExtendedFlag = 0x80000000u;

// ---------------------------------------------------------------------------------------------
// Reading

enum class TokenKind { kEnd, kWord, kNumber, kString, kPunct };

struct Token {
  TokenKind kind = TokenKind::kEnd;
  std::string text;
  int line = 0;
  bool line_start = false;  // the first token of its line
};

// Splits DBC text into words, numbers, strings and single-character punctuation. A sign
// belongs to a number only when a digit or a point follows it (`@1+ (` is a sign of its own).
class Lexer {
 public:
  Lexer(std::string_view text, std::string_view source) : text_(text), source_(source) {}

  Token next() {
    bool line_start = at_line_start_;
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '\n') {
        ++line_;
        line_start = true;
        ++pos_;
      } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
        ++pos_;
      } else if (c == '/' && pos_ + 1 < text_.size() && text_[pos_ + 1] == '/') {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;  // a // comment
      } else {
        break;
      }
    }
    at_line_start_ = false;
    Token t;
    t.line = line_;
    t.line_start = line_start;
    if (pos_ >= text_.size()) return t;
    const char c = text_[pos_];
    const auto is_digit = [&](std::size_t i) {
      return i < text_.size() && std::isdigit(static_cast<unsigned char>(text_[i])) != 0;
    };
    if (c == '"') {
      t.kind = TokenKind::kString;
      ++pos_;
      while (true) {
        if (pos_ >= text_.size()) {
          throw ConfigError(std::string(source_), t.line, "", "a string is not closed");
        }
        const char d = text_[pos_++];
        if (d == '"') break;
        if (d == '\\' && pos_ < text_.size()) {
          t.text += text_[pos_++];
          continue;
        }
        if (d == '\n') ++line_;
        t.text += d;
      }
    } else if (is_digit(pos_) || ((c == '-' || c == '+' || c == '.') && is_digit(pos_ + 1)) ||
               ((c == '-' || c == '+') && pos_ + 1 < text_.size() && text_[pos_ + 1] == '.' &&
                is_digit(pos_ + 2))) {
      t.kind = TokenKind::kNumber;
      const std::size_t begin = pos_;
      ++pos_;
      while (pos_ < text_.size()) {
        const char d = text_[pos_];
        const bool exponent_sign =
            (d == '-' || d == '+') && (text_[pos_ - 1] == 'e' || text_[pos_ - 1] == 'E');
        if (std::isalnum(static_cast<unsigned char>(d)) == 0 && d != '.' && !exponent_sign) break;
        ++pos_;
      }
      t.text = std::string(text_.substr(begin, pos_ - begin));
    } else if (std::isalpha(static_cast<unsigned char>(c)) != 0 || c == '_') {
      t.kind = TokenKind::kWord;
      const std::size_t begin = pos_;
      while (pos_ < text_.size() &&
             (std::isalnum(static_cast<unsigned char>(text_[pos_])) != 0 || text_[pos_] == '_')) {
        ++pos_;
      }
      t.text = std::string(text_.substr(begin, pos_ - begin));
    } else {
      t.kind = TokenKind::kPunct;
      t.text = std::string(1, c);
      ++pos_;
    }
    return t;
  }

 private:
  std::string_view text_;
  std::string_view source_;
  std::size_t pos_ = 0;
  int line_ = 1;
  bool at_line_start_ = true;
};

class Parser {
 public:
  Parser(std::string_view text, std::string_view source) : lex_(text, source), source_(source) {
    advance();
  }

  Dbc parse() {
    Dbc dbc;
    dbc.source = std::string(source_);
    DbcMessage* current = nullptr;
    while (tok_.kind != TokenKind::kEnd) {
      if (tok_.kind != TokenKind::kWord) {
        fail(tok_.line, "", "expected a keyword, got '" + tok_.text + "'");
      }
      const std::string keyword = tok_.text;
      const int line = tok_.line;
      if (keyword == "BO_") {
        advance();
        dbc.messages.push_back(read_message(line));
        current = &dbc.messages.back();
      } else if (keyword == "SG_") {
        if (current == nullptr) fail(line, "SG_", "a signal outside a message (BO_)");
        advance();
        read_signal(*current, line);
      } else if (keyword == "BA_") {
        advance();
        read_attribute(dbc);
        current = nullptr;
      } else if (keyword == "SIG_VALTYPE_") {
        advance();
        read_value_type(dbc);
        current = nullptr;
      } else if (keyword == "VERSION") {
        advance();
        expect(TokenKind::kString, "VERSION", "a string");
        current = nullptr;
      } else if (keyword == "NS_") {
        // NS_ : and then the keywords the file may use, one per line, up to BS_ (or whatever
        // statement comes first when BS_ is missing).
        advance();
        while (tok_.kind != TokenKind::kEnd &&
               !(tok_.line_start && tok_.kind == TokenKind::kWord &&
                 (tok_.text == "BS_" || tok_.text == "BU_" || tok_.text == "BO_"))) {
          advance();
        }
        current = nullptr;
      } else if (keyword == "BS_" || keyword == "BU_") {
        // Unterminated lists: up to the next statement at the start of a line.
        advance();
        while (tok_.kind != TokenKind::kEnd &&
               !(tok_.line_start && tok_.kind == TokenKind::kWord && is_statement(tok_.text))) {
          advance();
        }
        current = nullptr;
      } else {
        // CM_, BA_DEF_, BA_DEF_DEF_, VAL_, EV_, SIG_GROUP_, ...: all end with ';'.
        skip_statement(keyword, line);
        current = nullptr;
      }
    }
    return dbc;
  }

 private:
  static bool is_statement(const std::string& word) {
    static const char* const kKeywords[] = {"VERSION",       "NS_",          "BS_",
                                            "BU_",           "BO_",          "SG_",
                                            "CM_",           "BA_DEF_",      "BA_DEF_DEF_",
                                            "BA_",           "VAL_",         "VAL_TABLE_",
                                            "EV_",           "ENVVAR_DATA_", "SIG_VALTYPE_",
                                            "SIG_GROUP_",    "BO_TX_BU_",    "SGTYPE_",
                                            "SIG_TYPE_REF_", "BA_DEF_REL_",  "BA_DEF_DEF_REL_",
                                            "BA_REL_",       "SG_MUL_VAL_",  "CAT_DEF_",
                                            "CAT_",          "FILTER",       "BU_SG_REL_",
                                            "BU_EV_REL_",    "BU_BO_REL_",   "SGTYPE_VAL_"};
    return std::any_of(std::begin(kKeywords), std::end(kKeywords),
                       [&](const char* k) { return word == k; });
  }

  [[noreturn]] void fail(int line, const std::string& field, const std::string& reason) const {
    throw ConfigError(std::string(source_), line, field, reason);
  }

  void advance() { tok_ = lex_.next(); }

  std::string expect(TokenKind kind, const std::string& field, const char* what) {
    if (tok_.kind != kind) {
      fail(tok_.line, field,
           std::string("expected ") + what + ", got " +
               (tok_.kind == TokenKind::kEnd ? std::string("the end of the file")
                                             : "'" + tok_.text + "'"));
    }
    std::string text = tok_.text;
    advance();
    return text;
  }

  void expect_punct(char c, const std::string& field) {
    if (tok_.kind != TokenKind::kPunct || tok_.text[0] != c) {
      fail(tok_.line, field,
           std::string("expected '") + c + "', got " +
               (tok_.kind == TokenKind::kEnd ? std::string("the end of the file")
                                             : "'" + tok_.text + "'"));
    }
    advance();
  }

  double number(const std::string& field, const char* what) {
    const int line = tok_.line;
    const std::string s = expect(TokenKind::kNumber, field, what);
    const char* begin = s.data() + (s[0] == '+' ? 1 : 0);
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(begin, s.data() + s.size(), v);
    if (ec != std::errc() || ptr != s.data() + s.size() || !std::isfinite(v)) {
      fail(line, field, std::string(what) + ": not a number: '" + s + "'");
    }
    return v;
  }

  std::uint64_t unsigned_integer(const std::string& field, const char* what, std::uint64_t max) {
    const int line = tok_.line;
    const std::string s = expect(TokenKind::kNumber, field, what);
    std::uint64_t v = 0;
    const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || ptr != s.data() + s.size()) {
      fail(line, field, std::string(what) + ": expected a non-negative integer, got '" + s + "'");
    }
    if (v > max) fail(line, field, std::string(what) + " must be at most " + std::to_string(max));
    return v;
  }

  DbcMessage read_message(int line) {
    DbcMessage m;
    m.line = line;
    const std::string field = "BO_ " + tok_.text;
    const std::uint64_t raw = unsigned_integer(field, "the message id", 0xFFFFFFFFu);
    m.extended = (raw & kDbcExtendedFlag) != 0 || raw > kMaxStandardId;
    m.id = static_cast<std::uint32_t>(raw & ~kDbcExtendedFlag);
    if (m.id > kMaxExtendedId) fail(line, field, "the message id is above 29 bits");
    m.name = expect(TokenKind::kWord, field, "the message name");
    expect_punct(':', field);
    m.dlc = static_cast<std::uint8_t>(unsigned_integer(field, "the message length", 8));
    if (tok_.kind == TokenKind::kWord && !tok_.line_start) {
      m.sender = tok_.text;
      advance();
    }
    return m;
  }

  void read_signal(DbcMessage& m, int line) {
    DbcSignal s;
    s.line = line;
    s.name = expect(TokenKind::kWord, "SG_", "the signal name");
    const std::string field = "SG_ " + s.name;
    if (tok_.kind == TokenKind::kWord) {  // M (multiplexor) or mN (multiplexed)
      s.multiplexed = true;
      advance();
    }
    expect_punct(':', field);
    SignalSpec& spec = s.spec;
    spec.id = m.id;
    spec.extended = m.extended;
    spec.start_bit = static_cast<std::uint16_t>(unsigned_integer(field, "the start bit", 63));
    expect_punct('|', field);
    spec.length = static_cast<std::uint16_t>(unsigned_integer(field, "the length", 64));
    if (spec.length == 0) fail(line, field, "the length must be 1..64");
    expect_punct('@', field);
    // "1+" lexes as the number 1 and '+'; "0-" as 0 and '-'; "1" followed by "-5" never occurs
    // because a sign follows the order digit directly.
    const std::string order = expect(TokenKind::kNumber, field, "the byte order (0 or 1)");
    if (order == "1") {
      spec.byte_order = ByteOrder::kLittleEndian;
    } else if (order == "0") {
      spec.byte_order = ByteOrder::kBigEndian;
    } else {
      fail(line, field, "the byte order must be 0 (Motorola) or 1 (Intel), got '" + order + "'");
    }
    if (tok_.kind != TokenKind::kPunct || (tok_.text != "+" && tok_.text != "-")) {
      fail(line, field, "expected the sign, '+' or '-', after the byte order");
    }
    spec.is_signed = tok_.text == "-";
    advance();
    expect_punct('(', field);
    spec.scale = number(field, "the factor");
    expect_punct(',', field);
    spec.offset = number(field, "the offset");
    expect_punct(')', field);
    expect_punct('[', field);
    const double lo = number(field, "the minimum");
    expect_punct('|', field);
    const double hi = number(field, "the maximum");
    expect_punct(']', field);
    // [0|0] is DBC's "no range given".
    if (!(lo == 0.0 && hi == 0.0)) {
      spec.minimum = lo;
      spec.maximum = hi;
    }
    spec.unit = expect(TokenKind::kString, field, "the unit (a string)");
    // Receivers: one or more node names separated by commas, on the same line.
    while (tok_.kind == TokenKind::kWord && !tok_.line_start) {
      advance();
      if (tok_.kind == TokenKind::kPunct && tok_.text == ",") {
        advance();
      } else {
        break;
      }
    }
    if (spec.scale == 0.0) fail(line, field, "the factor must be nonzero");
    const SpecError e = validate(spec);
    if (e != SpecError::kNone) fail(line, field, to_string(e));
    for (const auto& other : m.signals) {
      if (other.name == s.name) fail(line, field, "a second signal of this name in " + m.name);
    }
    m.signals.push_back(std::move(s));
  }

  DbcMessage* find(Dbc& dbc, std::uint64_t raw_id) {
    const auto id = static_cast<std::uint32_t>(raw_id & ~kDbcExtendedFlag);
    const bool extended = (raw_id & kDbcExtendedFlag) != 0 || raw_id > kMaxStandardId;
    for (auto& m : dbc.messages) {
      if (m.id == id && m.extended == extended) return &m;
    }
    return nullptr;
  }

  // BA_ "Name" [BO_ id | SG_ id name | BU_ node | EV_ name] value ;
  void read_attribute(Dbc& dbc) {
    const int line = tok_.line;
    const std::string name = expect(TokenKind::kString, "BA_", "the attribute name");
    const std::string field = "BA_ \"" + name + "\"";
    if (tok_.kind == TokenKind::kWord && tok_.text == "BO_" &&
        (name == "GenMsgCycleTime" || name == "VFrameFormat")) {
      advance();
      const std::uint64_t raw = unsigned_integer(field, "the message id", 0xFFFFFFFFu);
      const double value = number(field, "the value");
      expect_punct(';', field);
      DbcMessage* m = find(dbc, raw);
      if (m == nullptr) return;  // an attribute of a message the file does not define: harmless
      if (name == "GenMsgCycleTime") {
        if (value < 0.0) fail(line, field, "a negative cycle time");
        m->cycle_s = value > 0.0 ? std::optional<double>(value * 1e-3) : std::nullopt;
      } else {
        m->j1939 = value == 3.0;  // the J1939PG entry of the usual VFrameFormat enum
      }
      return;
    }
    skip_statement("BA_", line);
  }

  // SIG_VALTYPE_ id name : 1 ; (0 integer, 1 IEEE float, 2 IEEE double).
  void read_value_type(Dbc& dbc) {
    const std::uint64_t raw = unsigned_integer("SIG_VALTYPE_", "the message id", 0xFFFFFFFFu);
    const std::string signal = expect(TokenKind::kWord, "SIG_VALTYPE_", "the signal name");
    if (tok_.kind == TokenKind::kPunct && tok_.text == ":") advance();
    const std::uint64_t type = unsigned_integer("SIG_VALTYPE_ " + signal, "the value type", 2);
    expect_punct(';', "SIG_VALTYPE_ " + signal);
    if (DbcMessage* m = find(dbc, raw)) {
      for (auto& s : m->signals) {
        if (s.name == signal) s.value_type = static_cast<int>(type);
      }
    }
  }

  void skip_statement(const std::string& keyword, int line) {
    if (tok_.kind == TokenKind::kWord && tok_.text == keyword) advance();
    while (true) {
      if (tok_.kind == TokenKind::kEnd) fail(line, keyword, "the statement has no ';'");
      if (tok_.kind == TokenKind::kPunct && tok_.text == ";") {
        advance();
        return;
      }
      advance();
    }
  }

  Lexer lex_;
  std::string_view source_;
  Token tok_;
};

// ---------------------------------------------------------------------------------------------
// Writing

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.15g", v);  // 15 digits: 0.01 deg stays 0.01, not 0.0100..02
  return buf;
}

std::string identifier(std::string_view name) {
  std::string out;
  for (const char c : name) {
    out += (std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_') ? c : '_';
  }
  if (out.empty() || std::isdigit(static_cast<unsigned char>(out[0])) != 0) out.insert(0, "_");
  return out;
}

// Text inside a DBC string: DBC has no escape that every reader takes, so '"' becomes '\''.
std::string dbc_string(std::string_view text) {
  std::string out = "\"";
  for (const char c : text) out += c == '"' ? '\'' : c;
  return out + "\"";
}

std::string hex(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%X", v);
  return buf;
}

struct OutSignal {
  std::string name;
  std::string owner;  // the joint, "pump", "heartbeat": names a frame of one owner
  std::string role;
  SignalSpec spec;  // scale, offset, min, max in spec.unit
  std::string receiver;
  std::string comment;
  std::vector<std::pair<int, std::string>> values;
};

struct OutMessage {
  std::string name;
  std::uint32_t id = 0;
  bool extended = false;
  std::uint8_t dlc = 0;
  std::string sender;
  double cycle_s = 0.0;
  bool j1939 = false;
  std::string comment;
  std::vector<OutSignal> signals;
};

// A mapping signal in the units its file wrote.
SignalSpec in_file_units(const SignalSpec& si) {
  SignalSpec s = si;
  const double k = si.unit_si;
  s.scale = si.scale / k;
  s.offset = si.offset / k;
  if (si.minimum) s.minimum = *si.minimum / k;
  if (si.maximum) s.maximum = *si.maximum / k;
  s.unit_si = 1.0;
  return s;
}

SignalSpec field(std::uint32_t id, std::uint16_t start, std::uint16_t length, double scale,
                 double offset, double lo, double hi, const char* unit) {
  SignalSpec s;
  s.id = id;
  s.extended = true;
  s.start_bit = start;
  s.length = length;
  s.scale = scale;
  s.offset = offset;
  s.minimum = lo;
  s.maximum = hi;
  s.unit = unit;
  return s;
}

const std::vector<std::pair<int, std::string>> kValveStates = {
    {0, "block"}, {1, "extend"}, {2, "retract"}, {3, "float"}, {15, "dont_care"}};
const std::vector<std::pair<int, std::string>> kFailSafeModes = {
    {0, "block"}, {1, "float"}, {3, "dont_care"}};

OutMessage avc_message(const JointMapping& jm) {
  const AvcOutput& a = jm.valve.avc;
  OutMessage m;
  std::uint32_t id = 0;
  j1939::make_id(a.priority, iso11783::kPgnAuxValveCommand0 + a.valve, a.source_address,
                 j1939::kGlobalAddress, id);
  m.id = id;
  m.extended = true;
  m.dlc = 8;
  m.name = "AuxValveCommand" + std::to_string(a.valve);
  m.sender = "craneassist";
  m.cycle_s = a.cycle_s;
  m.j1939 = true;
  m.comment = "ISO 11783-7 Auxiliary Valve " + std::to_string(a.valve) + " Command (PGN " +
              std::to_string(iso11783::kPgnAuxValveCommand0 + a.valve) + "), joint " + jm.name;
  const auto add = [&](const char* name, SignalSpec spec, const char* comment,
                       std::vector<std::pair<int, std::string>> values = {}) {
    m.signals.push_back({name, jm.name, name, spec, "machine", comment, std::move(values)});
  };
  add("PortFlowCommand", field(id, 0, 8, 0.4, 0, 0, 100, "%"), "port flow, 0..250 = 0..100 %");
  add("ResolutionMode", field(id, 8, 2, 1, 0, 0, 3, ""),
      "0 standard resolution only, 1 extended and standard valid",
      {{0, "standard"}, {1, "extended_and_standard"}, {3, "dont_care"}});
  add("ValveState", field(id, 16, 4, 1, 0, 0, 15, ""), "commanded valve state", kValveStates);
  add("FailSafeMode", field(id, 22, 2, 1, 0, 0, 3, ""), "the valve's state when commands stop",
      kFailSafeModes);
  add("PortFlowCommandExtended", field(id, 24, 16, 0.0015625, 0, 0, 100, "%"),
      "port flow, extended resolution, 64000 = 100 %; 0xFFFF when the mode is 0");
  return m;
}

// A J1939 broadcast message of fixed layout: its identifier from priority, PGN and sender.
OutMessage j1939_message(std::string name, std::uint8_t priority, std::uint32_t pgn_value,
                         std::uint8_t source, std::string sender, std::string comment) {
  OutMessage m;
  std::uint32_t id = 0;
  j1939::make_id(priority, pgn_value, source, j1939::kGlobalAddress, id);
  m.name = std::move(name);
  m.id = id;
  m.extended = true;
  m.dlc = 8;
  m.sender = std::move(sender);
  m.j1939 = true;
  m.comment = std::move(comment);
  return m;
}

void add_field(OutMessage& m, const char* name, std::uint16_t start, std::uint16_t length,
               double scale, double offset, double lo, double hi, const char* unit,
               const char* comment, std::vector<std::pair<int, std::string>> values = {}) {
  const std::string receiver = m.sender == "craneassist" ? "machine" : "craneassist";
  m.signals.push_back({name, m.name, name, field(m.id, start, length, scale, offset, lo, hi, unit),
                       receiver, comment, std::move(values)});
}

std::string hex_address(std::uint8_t a) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%02X", static_cast<unsigned>(a));
  return buf;
}

// J1939-81 Address Claimed from `source`: craneassist's (its NAME, sent at start-up, on a request
// and on a contending claim) or a supervised node's. A Cannot Claim comes from the null address
// 0xFE and is not described.
OutMessage address_claim_message(std::uint8_t source, const std::string& sender,
                                 const std::string& comment) {
  OutMessage m = j1939_message("AddressClaimed_" + hex_address(source), j1939::kNetworkPriority,
                               j1939::kPgnAddressClaimed, source, sender,
                               "J1939-81 Address Claimed (PGN 60928) " + comment);
  add_field(m, "IdentityNumber", 0, 21, 1, 0, 0, 2097151, "", "");
  add_field(m, "ManufacturerCode", 21, 11, 1, 0, 0, 2047, "", "");
  add_field(m, "EcuInstance", 32, 3, 1, 0, 0, 7, "", "");
  add_field(m, "FunctionInstance", 35, 5, 1, 0, 0, 31, "", "");
  add_field(m, "Function", 40, 8, 1, 0, 0, 255, "", "");
  add_field(m, "Reserved", 48, 1, 1, 0, 0, 1, "", "sent as 0");
  add_field(m, "VehicleSystem", 49, 7, 1, 0, 0, 127, "", "");
  add_field(m, "VehicleSystemInstance", 56, 4, 1, 0, 0, 15, "", "");
  add_field(m, "IndustryGroup", 60, 3, 1, 0, 0, 7, "", "");
  add_field(m, "ArbitraryAddressCapable", 63, 1, 1, 0, 0, 1, "", "");
  return m;
}

// ISO 11783-7 Auxiliary Valve Estimated Flow of a supervised valve (docs/can.md, "Valve
// supervision"). The mapping does not state the valve's send rate, so no cycle time is given.
OutMessage estimated_flow_message(const JointMapping& jm) {
  const std::uint8_t valve = jm.valve.avc.valve;
  OutMessage m = j1939_message(
      "AuxValveEstimatedFlow" + std::to_string(valve), iso11783::kDefaultPriority,
      iso11783::kPgnAuxValveEstimatedFlow0 + valve, jm.reply->source_address, "machine",
      "ISO 11783-7 Auxiliary Valve " + std::to_string(valve) + " Estimated Flow (PGN " +
          std::to_string(iso11783::kPgnAuxValveEstimatedFlow0 + valve) + "), joint " + jm.name +
          ": supervised, at least every " + number_text(jm.reply->timeout_s * 1e3) + " ms");
  add_field(m, "ExtendPortEstimatedFlow", 0, 8, 1, -125, -125, 125, "%", "");
  add_field(m, "RetractPortEstimatedFlow", 8, 8, 1, -125, -125, 125, "%", "");
  auto states = kValveStates;
  states.insert(states.end() - 1, {14, "error"});
  add_field(m, "ValveState", 16, 4, 1, 0, 0, 15, "", "the valve's state", states);
  add_field(m, "FailSafeMode", 22, 2, 1, 0, 0, 3, "", "", kFailSafeModes);
  add_field(m, "LimitStatus", 29, 3, 1, 0, 0, 7, "", "6: non-recoverable fault",
            {{0, "not_limited"},
             {1, "operator_limited"},
             {2, "limited_high"},
             {3, "limited_low"},
             {6, "non_recoverable_fault"},
             {7, "not_available"}});
  return m;
}

// J1939-73 DM1 of a supervised node, single-frame form. The SPN's 19 bits are split as the frame
// splits them: the low 16 in bytes 3-4, the high 3 in byte 5 bits 6-8 (SPN = low + high * 65536).
OutMessage dm1_message(std::uint8_t source) {
  OutMessage m = j1939_message(
      "DM1_" + hex_address(source), j1939::kNetworkPriority, j1939::kPgnDm1, source, "machine",
      "J1939-73 DM1 Active Diagnostic Trouble Codes of node 0x" + hex_address(source) +
          ": an active DTC or the red stop lamp stops the crane (docs/can.md)");
  const std::vector<std::pair<int, std::string>> lamp = {
      {0, "off"}, {1, "on"}, {2, "error"}, {3, "not_available"}};
  add_field(m, "ProtectLamp", 0, 2, 1, 0, 0, 3, "", "", lamp);
  add_field(m, "AmberWarningLamp", 2, 2, 1, 0, 0, 3, "", "", lamp);
  add_field(m, "RedStopLamp", 4, 2, 1, 0, 0, 3, "", "", lamp);
  add_field(m, "MalfunctionIndicatorLamp", 6, 2, 1, 0, 0, 3, "", "", lamp);
  add_field(m, "LampFlash", 8, 8, 1, 0, 0, 255, "", "");
  add_field(m, "SpnLow", 16, 16, 1, 0, 0, 65535, "", "SPN bits 0-15");
  add_field(m, "Fmi", 32, 5, 1, 0, 0, 31, "", "failure mode identifier");
  add_field(m, "SpnHigh", 37, 3, 1, 0, 0, 7, "", "SPN bits 16-18");
  add_field(m, "OccurrenceCount", 40, 7, 1, 0, 0, 127, "", "");
  add_field(m, "SpnConversionMethod", 47, 1, 1, 0, 0, 1, "", "");
  m.cycle_s = 1.0;
  return m;
}

OutMessage heartbeat_message(const HeartbeatSpec& hb) {
  OutMessage m;
  m.name = "craneassist_heartbeat";
  m.id = hb.id;
  m.extended = hb.extended;
  m.dlc = 8;
  m.sender = "craneassist";
  m.cycle_s = hb.cycle_s;
  m.comment =
      "craneassist's alive message; the machine blocks every section when the counter "
      "has not advanced for " +
      number_text(hb.timeout_s * 1e3) + " ms (docs/can.md)";
  const auto add = [&](const char* name, std::uint16_t start, double hi, const char* comment,
                       std::vector<std::pair<int, std::string>> values = {}) {
    SignalSpec s = field(hb.id, start, 8, 1, 0, 0, hi, "");
    s.extended = hb.extended;
    m.signals.push_back({name, "heartbeat", name, s, "machine", comment, std::move(values)});
  };
  add("AliveCounter", 0, 255, "+1 per message, wrapping");
  add("State", 8, 2, "", {{0, "disabled"}, {1, "enabled"}, {2, "fault"}});
  add("FaultReason", 16, 255, "the latched fault's code, docs/can.md (Heartbeat)");
  return m;
}

// Gathers the signals of one direction into messages by identifier.
class Messages {
 public:
  void add(const OutSignal& s, const std::string& sender, double cycle_s) {
    for (auto& m : list_) {
      if (m.id == s.spec.id && m.extended == s.spec.extended) {
        m.signals.push_back(s);
        m.dlc = std::max(m.dlc, required_dlc(s.spec));
        return;
      }
    }
    OutMessage m;
    m.id = s.spec.id;
    m.extended = s.spec.extended;
    m.dlc = required_dlc(s.spec);
    m.sender = sender;
    m.cycle_s = cycle_s;
    m.signals.push_back(s);
    list_.push_back(std::move(m));
  }
  void add_message(OutMessage m) { list_.push_back(std::move(m)); }

  // Names each gathered message after its signals: one signal gives its own name, several of
  // one owner the owner and their common role ("slew_pressure"), mixed owners the identifier.
  std::vector<OutMessage> finish() {
    std::map<std::string, int> used;
    for (auto& m : list_) {
      if (m.name.empty()) {
        bool one_owner = true;
        for (const auto& s : m.signals) one_owner = one_owner && s.owner == m.signals[0].owner;
        if (m.signals.size() == 1) {
          m.name = m.signals[0].name;
        } else if (one_owner) {
          std::string common = m.signals[0].role;
          for (const auto& s : m.signals) {
            std::size_t n = 0;
            while (n < common.size() && n < s.role.size() && common[n] == s.role[n]) ++n;
            common.resize(n);
          }
          while (!common.empty() && common.back() == '_') common.pop_back();
          m.name = identifier(m.signals[0].owner) + (common.empty() ? "" : "_" + common);
        } else {
          m.name = "frame_" + hex(m.id);
        }
      }
      if (used[m.name]++ > 0) m.name += "_" + hex(m.id);
    }
    return list_;
  }

 private:
  std::vector<OutMessage> list_;
};

std::uint32_t dbc_id(const OutMessage& m) {
  return m.extended ? (m.id | kDbcExtendedFlag) : m.id;
}

}  // namespace

const DbcMessage* Dbc::message(std::string_view name) const {
  for (const auto& m : messages) {
    if (m.name == name) return &m;
  }
  return nullptr;
}

Dbc parse_dbc(std::string_view text, std::string_view source_name) {
  return Parser(text, source_name).parse();
}

Dbc load_dbc(const std::filesystem::path& path) {
  std::string text;
  try {
    text = files::read_text_file(path, files::kMaxDbcBytes, "DBC");
  } catch (const files::ReadError& e) {
    throw ConfigError(e.file(), 0, "", e.reason());
  }
  return parse_dbc(text, path.string());
}

std::string write_dbc(const CanMapping& mapping, std::string_view title) {
  Messages messages;
  std::optional<std::uint8_t> station;  // craneassist's J1939 address, from its AVC outputs
  for (const auto& jm : mapping.joints) {
    const std::string owner = identifier(jm.name);
    if (jm.valve.kind == ValveOutputKind::kIso11783Avc) {
      messages.add_message(avc_message(jm));
      station = jm.valve.avc.source_address;
    } else {
      const SignalSpec s = in_file_units(jm.valve.signal.signal);
      messages.add({owner + "_valve_command",
                    owner,
                    "valve_command",
                    s,
                    "machine",
                    "joint " + jm.name + ": valve command, negative = retract",
                    {}},
                   "craneassist", jm.valve.signal.cycle_s);
    }
  }
  if (mapping.heartbeat) messages.add_message(heartbeat_message(*mapping.heartbeat));
  if (mapping.address_claim) {
    char name[24];
    std::snprintf(name, sizeof name, "0x%016llX",
                  static_cast<unsigned long long>(mapping.address_claim->name));
    messages.add_message(
        address_claim_message(mapping.address_claim->address, "craneassist",
                              "of craneassist, NAME " + std::string(name) +
                                  ", before it sends anything from this address (docs/can.md)"));
    station = mapping.address_claim->address;
  }
  // Feedback: what the machine sends. Its cycle is the machine's; the mapping does not say it.
  for (const auto& jm : mapping.joints) {
    const std::string owner = identifier(jm.name);
    const auto feedback = [&](const char* role, const SignalSpec& spec, const char* what) {
      messages.add({owner + "_" + role,
                    owner,
                    role,
                    in_file_units(spec),
                    "craneassist",
                    "joint " + jm.name + ": " + what,
                    {}},
                   "machine", 0.0);
    };
    feedback("position", jm.position, "position");
    if (jm.pressure_a) feedback("pressure_a", *jm.pressure_a, "cylinder pressure, piston side");
    if (jm.pressure_b) feedback("pressure_b", *jm.pressure_b, "cylinder pressure, rod side");
  }
  // The valves' replies: Estimated Flow of ISO 11783 valves, a driver's status signal; DM1.
  for (const auto& jm : mapping.joints) {
    if (!jm.reply) continue;
    if (jm.valve.kind == ValveOutputKind::kIso11783Avc) {
      messages.add_message(estimated_flow_message(jm));
    } else {
      const std::string owner = identifier(jm.name);
      std::vector<std::pair<int, std::string>> ok;
      for (const std::uint64_t v : jm.reply->ok_values) ok.emplace_back(static_cast<int>(v), "ok");
      messages.add({owner + "_valve_status", owner, "valve_status", in_file_units(jm.reply->status),
                    "craneassist",
                    "joint " + jm.name +
                        ": the valve driver's status; a value not marked ok is "
                        "a fault, supervised, at least every " +
                        number_text(jm.reply->timeout_s * 1e3) + " ms",
                    ok},
                   "machine", 0.0);
    }
  }
  if (mapping.dm1) {
    for (const std::uint8_t sa : mapping.dm1->source_addresses) {
      messages.add_message(dm1_message(sa));
    }
  }
  // The supervised J1939 nodes claim their addresses too.
  std::vector<std::uint8_t> nodes;
  for (const auto& jm : mapping.joints) {
    if (jm.reply && jm.valve.kind == ValveOutputKind::kIso11783Avc) {
      nodes.push_back(jm.reply->source_address);
    }
  }
  if (mapping.dm1) {
    nodes.insert(nodes.end(), mapping.dm1->source_addresses.begin(),
                 mapping.dm1->source_addresses.end());
  }
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  for (const std::uint8_t sa : nodes) {
    if (mapping.address_claim && sa == mapping.address_claim->address) continue;
    messages.add_message(address_claim_message(sa, "machine", "of a supervised node"));
  }
  if (mapping.pump.pressure) {
    messages.add({"pump_pressure",
                  "pump",
                  "pressure",
                  in_file_units(*mapping.pump.pressure),
                  "craneassist",
                  "pump supply pressure",
                  {}},
                 "machine", 0.0);
  }
  if (mapping.pump.flow) {
    messages.add({"pump_flow",
                  "pump",
                  "flow",
                  in_file_units(*mapping.pump.flow),
                  "craneassist",
                  "pump delivered flow",
                  {}},
                 "machine", 0.0);
  }
  if (mapping.grapple.swing_radial && mapping.grapple.swing_tangential) {
    messages.add({"grapple_swing_radial",
                  "grapple",
                  "swing_radial",
                  in_file_units(*mapping.grapple.swing_radial),
                  "craneassist",
                  "grapple swing from the vertical towards the reach",
                  {}},
                 "machine", 0.0);
    messages.add({"grapple_swing_tangential",
                  "grapple",
                  "swing_tangential",
                  in_file_units(*mapping.grapple.swing_tangential),
                  "craneassist",
                  "grapple swing from the vertical across the reach (towards a positive slew)",
                  {}},
                 "machine", 0.0);
  }
  const std::vector<OutMessage> list = messages.finish();
  const bool j1939 = std::any_of(list.begin(), list.end(), [](const auto& m) { return m.j1939; });

  std::ostringstream out;
  out << "VERSION " << dbc_string("craneassist " + std::string(title)) << "\n\n\n";
  out << "NS_ :\n";
  for (const char* ns :
       {"NS_DESC_", "CM_", "BA_DEF_", "BA_", "VAL_", "BA_DEF_DEF_", "SIG_VALTYPE_", "BO_TX_BU_"}) {
    out << "\t" << ns << "\n";
  }
  out << "\nBS_:\n\nBU_: craneassist machine\n\n";
  for (const auto& m : list) {
    out << "\nBO_ " << dbc_id(m) << " " << m.name << ": " << static_cast<int>(m.dlc) << " "
        << m.sender << "\n";
    for (const auto& s : m.signals) {
      const SignalSpec& p = s.spec;
      out << " SG_ " << s.name << " : " << p.start_bit << "|" << p.length << "@"
          << (p.byte_order == ByteOrder::kLittleEndian ? "1" : "0") << (p.is_signed ? "-" : "+")
          << " (" << number_text(p.scale) << "," << number_text(p.offset) << ") ["
          << number_text(p.minimum.value_or(0.0)) << "|" << number_text(p.maximum.value_or(0.0))
          << "] " << dbc_string(p.unit) << " " << s.receiver << "\n";
    }
  }
  out << "\n\n";
  out << "CM_ "
      << dbc_string("Generated by craneassist can dbc from " + std::string(title) +
                    "; scalings and units as the mapping states them (docs/can.md)")
      << ";\n";
  for (const auto& m : list) {
    if (!m.comment.empty()) out << "CM_ BO_ " << dbc_id(m) << " " << dbc_string(m.comment) << ";\n";
    for (const auto& s : m.signals) {
      if (!s.comment.empty()) {
        out << "CM_ SG_ " << dbc_id(m) << " " << s.name << " " << dbc_string(s.comment) << ";\n";
      }
    }
  }
  out << "BA_DEF_  \"ProtocolType\" STRING ;\n";
  out << "BA_DEF_ BU_  \"NmStationAddress\" INT 0 255;\n";
  out << "BA_DEF_ BO_  \"GenMsgCycleTime\" INT 0 65535;\n";
  out << "BA_DEF_ BO_  \"GenMsgSendType\" ENUM  \"Cyclic\",\"NoMsgSendType\";\n";
  out << "BA_DEF_ BO_  \"VFrameFormat\" ENUM  \"StandardCAN\",\"ExtendedCAN\",\"reserved\","
         "\"J1939PG\";\n";
  out << "BA_DEF_DEF_  \"ProtocolType\" \"\";\n";
  out << "BA_DEF_DEF_  \"NmStationAddress\" 254;\n";
  out << "BA_DEF_DEF_  \"GenMsgCycleTime\" 0;\n";
  out << "BA_DEF_DEF_  \"GenMsgSendType\" \"NoMsgSendType\";\n";
  out << "BA_DEF_DEF_  \"VFrameFormat\" \"StandardCAN\";\n";
  if (j1939) out << "BA_ \"ProtocolType\" \"J1939\";\n";
  if (station) {
    out << "BA_ \"NmStationAddress\" BU_ craneassist " << static_cast<int>(*station) << ";\n";
  }
  for (const auto& m : list) {
    if (m.cycle_s > 0.0) {
      out << "BA_ \"GenMsgCycleTime\" BO_ " << dbc_id(m) << " "
          << static_cast<long>(std::lround(m.cycle_s * 1e3)) << ";\n";
      out << "BA_ \"GenMsgSendType\" BO_ " << dbc_id(m) << " 0;\n";
    }
    out << "BA_ \"VFrameFormat\" BO_ " << dbc_id(m) << " " << (m.j1939 ? 3 : (m.extended ? 1 : 0))
        << ";\n";
  }
  for (const auto& m : list) {
    for (const auto& s : m.signals) {
      if (s.values.empty()) continue;
      out << "VAL_ " << dbc_id(m) << " " << s.name;
      for (const auto& [v, text] : s.values) out << " " << v << " \"" << text << "\"";
      out << " ;\n";
    }
  }
  return out.str();
}

}  // namespace craneassist::can
