#include "craneassist/control/log_fields.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <type_traits>

namespace craneassist::control {

namespace {

template <class T>
inline constexpr bool kIsArray = false;
template <std::size_t N>
inline constexpr bool kIsArray<std::array<double, N>> = true;

const LogRow kEmptyRow{};  // for the descriptions (the values are not read)

bool present(const Field& f, bool base) {
  return base || !f.base_only;
}

void append_number(double x, std::string& out) {
  if (!std::isfinite(x)) {
    out += "null";
    return;
  }
  char buf[32];
  const auto end = std::to_chars(buf, buf + sizeof buf, x).ptr;  // shortest round trip
  out.append(buf, end);
}

template <class T>
void append_value(const Field& f, const T& value, int dof, std::string& out) {
  if constexpr (kIsArray<T>) {
    if (f.per_joint) {
      out += '[';
      for (int i = 0; i < dof; ++i) {
        if (i > 0) out += ',';
        append_number(value[static_cast<std::size_t>(i)], out);
      }
      out += ']';
    } else {
      out += '{';
      for (std::size_t k = 0; k < value.size(); ++k) {
        if (k > 0) out += ',';
        out += '"';
        out += list_item(f.components, k);
        out += "\":";
        append_number(value[k], out);
      }
      out += '}';
    }
  } else if constexpr (std::is_same_v<T, bool>) {
    out += value ? "true" : "false";
  } else if constexpr (std::is_same_v<T, const char*>) {
    append_json_string(value != nullptr ? value : "", out);
  } else if constexpr (std::is_integral_v<T>) {
    out += std::to_string(value);
  } else {
    append_number(value, out);
  }
}

// One string "type" per field, as Foxglove-class viewers parse JSON Schema (Foxglove, Lichtblick:
// no type lists, no "null"). A value that is not a number (NaN, infinite) is still written as
// null (append_number): the descriptions say so, and a viewer plots a gap there.
template <class T>
std::string schema_of(const Field& f, const T& value) {
  const std::string number = R"({"type":"number"})";
  std::string s;
  if constexpr (kIsArray<T>) {
    if (f.per_joint) {
      s = R"({"type":"array","items":)" + number;
    } else {
      s = R"({"type":"object","properties":{)";
      std::string required;
      for (std::size_t k = 0; k < value.size(); ++k) {
        const std::string c(list_item(f.components, k));
        if (k > 0) {
          s += ',';
          required += ',';
        }
        s += '"' + c + "\":" + number;
        required += '"' + c + '"';
      }
      s += "},\"required\":[" + required + "]";
    }
  } else if constexpr (std::is_same_v<T, bool>) {
    s = R"({"type":"boolean")";
  } else if constexpr (std::is_same_v<T, const char*>) {
    s = R"({"type":"string")";
  } else if constexpr (std::is_integral_v<T>) {
    s = R"({"type":"integer")";
  } else {
    s = R"({"type":"number")";
  }
  std::string description;
  append_json_string(
      std::string(f.unit) + ": " + f.meaning +
          (kIsArray<T> || std::is_floating_point_v<T> ? " (null: not a number)" : ""),
      description);
  return s + ",\"description\":" + description + "}";
}

}  // namespace

std::string_view list_item(std::string_view list, std::size_t k, std::string_view separator) {
  for (std::size_t i = 0; i < k; ++i) {
    const auto at = list.find(separator);
    if (at == std::string_view::npos) break;  // fewer items: the last one
    list.remove_prefix(at + separator.size());
  }
  return list.substr(0, list.find(separator));
}

void append_json_string(std::string_view text, std::string& out) {
  out += '"';
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20) {
      static constexpr char kHex[] = "0123456789abcdef";
      out += "\\u00";
      out += kHex[u >> 4];
      out += kHex[u & 15];
    } else {
      out += c;
    }
  }
  out += '"';
}

const char* to_string(FieldGroup group) noexcept {
  switch (group) {
    case FieldGroup::kStatus:
      return "status";
    case FieldGroup::kCommand:
      return "command";
    case FieldGroup::kJoints:
      return "joints";
    case FieldGroup::kHydraulics:
      return "hydraulics";
    case FieldGroup::kLimits:
      return "limits";
    case FieldGroup::kPolytope:
      return "polytope";
    case FieldGroup::kLoads:
      return "loads";
    case FieldGroup::kBase:
      return "base";
  }
  return "?";
}

std::vector<Field> field_table() {
  std::vector<Field> fields;
  LogRow row;
  visit_fields(row, [&](const Field& f, const auto&) { fields.push_back(f); });
  return fields;
}

std::string csv_header(int dof, bool base) {
  std::string h;
  visit_fields(kEmptyRow, [&](const Field& f, const auto&) {
    if (f.csv == nullptr || !present(f, base)) return;
    if (f.per_joint) {
      for (int i = 1; i <= dof; ++i) {
        std::string column(f.csv);
        column.replace(column.find('#'), 1, std::to_string(i));
        if (!h.empty()) h += ',';
        h += column;
      }
    } else {
      if (!h.empty()) h += ',';
      h += f.csv;
    }
  });
  return h;
}

void append_group_json(const LogRow& row, int dof, FieldGroup group, std::string& out) {
  out += '{';
  bool first = true;
  visit_fields(row, [&](const Field& f, const auto& value) {
    if (f.group != group) return;
    if (!first) out += ',';
    first = false;
    out += '"';
    out += f.name;
    out += "\":";
    append_value(f, value, dof, out);
  });
  out += '}';
}

std::string group_json_schema(FieldGroup group) {
  std::string properties, required;
  visit_fields(kEmptyRow, [&](const Field& f, const auto& value) {
    if (f.group != group) return;
    if (!properties.empty()) {
      properties += ',';
      required += ',';
    }
    properties += '"' + std::string(f.name) + "\":" + schema_of(f, value);
    required += '"' + std::string(f.name) + '"';
  });
  return std::string(R"({"$schema":"https://json-schema.org/draft/2020-12/schema",)") +
         R"("title":"craneassist/)" + to_string(group) +
         R"j(","description":"craneassist's per-cycle values of this group (docs/log-format.md)",)j" +
         R"("type":"object","properties":{)" + properties + "},\"required\":[" + required + "]}";
}

std::vector<FlatField> flat_fields(int dof, bool base) {
  std::vector<FlatField> names;
  visit_fields(kEmptyRow, [&](const Field& f, const auto& value) {
    using T = std::decay_t<decltype(value)>;
    if (!present(f, base) || std::is_same_v<T, const char*>) return;
    if constexpr (kIsArray<T>) {
      if (f.per_joint) {
        for (int i = 1; i <= dof; ++i) {
          names.push_back({std::string(f.name) + "." + std::to_string(i), f.unit});
        }
      } else {
        for (std::size_t k = 0; k < value.size(); ++k) {
          // A vector of mixed units ("m, m, rad") lists one per component.
          names.push_back({std::string(f.name) + "." + std::string(list_item(f.components, k)),
                           std::string(list_item(f.unit, k, ", "))});
        }
      }
    } else {
      names.push_back({f.name, f.unit});
    }
  });
  return names;
}

int flat_field_values(const LogRow& row, int dof, bool base, double* out, int size) noexcept {
  int n = 0;
  const auto put = [&](double x) {
    if (n < size) out[n++] = x;
  };
  visit_fields(row, [&](const Field& f, const auto& value) {
    using T = std::decay_t<decltype(value)>;
    if (!present(f, base)) return;
    if constexpr (kIsArray<T>) {
      const std::size_t count = f.per_joint ? static_cast<std::size_t>(dof) : value.size();
      for (std::size_t k = 0; k < count && k < value.size(); ++k) put(value[k]);
    } else if constexpr (!std::is_same_v<T, const char*>) {
      put(static_cast<double>(value));
    }
  });
  return n;
}

std::string fields_markdown() {
  std::string md =
      "| field | unit | source | group | CSV columns | DDS member | meaning |\n"
      "| --- | --- | --- | --- | --- | --- | --- |\n";
  for (const Field& f : field_table()) {
    std::string csv = f.csv == nullptr ? std::string("-") : "`" + std::string(f.csv) + "`";
    for (std::size_t p = 0; (p = csv.find(',', p)) != std::string::npos; p += 4) {
      csv.replace(p, 1, "`, `");
    }
    if (f.per_joint && f.csv != nullptr) csv += " (# = 1..n)";
    if (f.base_only && f.csv != nullptr) csv += " (with a base)";
    md += "| `" + std::string(f.name) + "` | " + f.unit + " | " + f.source + " | " +
          to_string(f.group) + " | " + csv + " | " +
          (f.dds == nullptr ? std::string("fields only") : "`" + std::string(f.dds) + "`") + " | " +
          f.meaning + " |\n";
  }
  return md;
}

}  // namespace craneassist::control
