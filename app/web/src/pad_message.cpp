#include "pad_message.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

namespace craneassist::web {

bool parse_pad_message(std::string_view text, PadMessage& out) noexcept {
  try {
    const auto msg = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (!msg.is_object()) return false;
    const auto type = msg.find("type");
    const auto axes = msg.find("axes");
    const auto deadman = msg.find("deadman");
    if (type == msg.end() || !type->is_string() || type->get<std::string>() != "pad" ||
        axes == msg.end() || !axes->is_array() || axes->size() > out.axes.size() ||
        deadman == msg.end() || !deadman->is_boolean()) {
      return false;
    }
    out.axes.fill(0.0);
    std::size_t i = 0;
    for (const auto& a : *axes) {
      if (!a.is_number()) return false;
      const double v = a.get<double>();
      if (!std::isfinite(v) || std::abs(v) > 1.0) return false;
      out.axes[i++] = v;
    }
    out.deadman = deadman->get<bool>();
    return true;
  } catch (...) {  // nlohmann's allocation or conversion failures: malformed
    return false;
  }
}

}  // namespace craneassist::web
