// The page's stick state, as it arrives over the WebSocket (docs/web.md):
//   {"type":"pad","axes":[lx,ly,rx,ry,lt,rt],"deadman":true}
// Up to six axes, each a finite number in -1..1, and the deadman as a boolean; anything else is
// malformed. Bytes from outside: parse_pad_message never throws and never reads past the text.
#pragma once

#include <array>
#include <cstddef>
#include <string_view>

namespace craneassist::web {

struct PadMessage {
  std::array<double, 6> axes{};  // missing trailing axes are 0
  bool deadman = false;
};

// True and `out` filled when `text` is a valid stick state; false (out unspecified) otherwise.
bool parse_pad_message(std::string_view text, PadMessage& out) noexcept;

}  // namespace craneassist::web
