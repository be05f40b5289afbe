#include "formats/ros2msg.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <functional>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/file_text.h"

namespace exotwin {
namespace {

// The builtin types of ROS 2 interfaces (docs.ros.org "Interfaces": field types) and their CDR size.
struct Builtin {
  const char* name;
  int size;  // bytes; 0: string
  MsgValue::Kind kind;
};
constexpr Builtin kBuiltins[] = {
    {"bool", 1, MsgValue::kBool},     {"byte", 1, MsgValue::kUint},    {"char", 1, MsgValue::kUint},
    {"int8", 1, MsgValue::kInt},      {"uint8", 1, MsgValue::kUint},   {"int16", 2, MsgValue::kInt},
    {"uint16", 2, MsgValue::kUint},   {"int32", 4, MsgValue::kInt},    {"uint32", 4, MsgValue::kUint},
    {"int64", 8, MsgValue::kInt},     {"uint64", 8, MsgValue::kUint},  {"float32", 4, MsgValue::kFloat},
    {"float64", 8, MsgValue::kFloat}, {"string", 0, MsgValue::kString},
};

const Builtin* FindBuiltin(const std::string& type) {
  for (const Builtin& b : kBuiltins)
    if (type == b.name) return &b;
  return nullptr;
}

// Deeper nesting than this is refused (a bound on the decoder's recursion; ROS messages nest a few
// levels).
constexpr int kMaxDepth = 64;

bool IsIdentifier(const std::string& s) {
  if (s.empty() || !std::isalpha(static_cast<unsigned char>(s[0]))) return false;
  for (char c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
  return true;
}

// "pkg/msg/Type" -> "pkg/Type".
std::string Normalized(const std::string& name) {
  const size_t a = name.find('/');
  if (a == std::string::npos) return name;
  const size_t b = name.find('/', a + 1);
  if (b != std::string::npos && name.compare(a + 1, b - a - 1, "msg") == 0) return name.substr(0, a) + name.substr(b);
  return name;
}

std::string Package(const std::string& name) {
  const size_t a = name.find('/');
  return a == std::string::npos ? "" : name.substr(0, a);
}

bool ParseCount(const std::string& s, uint64_t* v) {
  if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos) return false;
  *v = std::stoull(s);
  return true;
}

// The bytes of one CDR message after the encapsulation header, with alignment counted from there.
class CdrReader {
 public:
  CdrReader(const std::string& bytes, bool little, const std::string& where)
      : p_(bytes.data() + 4), n_(bytes.size() - 4), little_(little), where_(where) {}

  uint64_t Uint(int size, const std::string& field) {
    const size_t pad = (size - pos_ % size) % size;
    Need(pad + size, field);
    pos_ += pad;
    uint64_t v = 0;
    for (int k = 0; k < size; ++k) {
      const uint64_t byte = static_cast<unsigned char>(p_[pos_ + (little_ ? size - 1 - k : k)]);
      v = (v << 8) | byte;
    }
    pos_ += size;
    return v;
  }
  std::string Bytes(uint64_t n, const std::string& field) {
    Need(n, field);
    std::string s(p_ + pos_, static_cast<size_t>(n));
    pos_ += n;
    return s;
  }
  size_t left() const { return n_ - pos_; }
  [[noreturn]] void Fail(const std::string& field, const std::string& what) const {
    throw InputError(where_ + ": field " + field + " (byte " + std::to_string(pos_ + 4) + " of the message): " + what);
  }

 private:
  void Need(uint64_t n, const std::string& field) const {
    if (n > n_ - pos_)
      Fail(field, "needs " + std::to_string(n) + " bytes, the message holds " + std::to_string(n_ - pos_) +
                      " more (a truncated message, or one of another type)");
  }
  const char* p_;
  size_t n_, pos_ = 0;
  bool little_;
  const std::string& where_;
};

MsgValue DecodeBuiltin(CdrReader& r, const Builtin& b, uint64_t string_bound, const std::string& field) {
  MsgValue v;
  v.kind = b.kind;
  if (b.size == 0) {
    const uint64_t len = r.Uint(4, field);
    if (len > r.left()) r.Fail(field, "a string of " + std::to_string(len) + " bytes, the message holds " +
                                          std::to_string(r.left()) + " more");
    v.s = r.Bytes(len, field);
    if (!v.s.empty() && v.s.back() == '\0') v.s.pop_back();
    if (string_bound > 0 && v.s.size() > string_bound)
      r.Fail(field, "a string of " + std::to_string(v.s.size()) + " bytes, its type bounds it to " +
                        std::to_string(string_bound));
    return v;
  }
  const uint64_t raw = r.Uint(b.size, field);
  switch (b.kind) {
    case MsgValue::kBool: v.i = raw != 0; break;
    case MsgValue::kUint: v.u = raw; break;
    case MsgValue::kInt: {  // sign-extended from size bytes
      const int shift = 64 - 8 * b.size;
      v.i = static_cast<int64_t>(raw << shift) >> shift;
      break;
    }
    default:
      if (b.size == 4) {
        const uint32_t bits = static_cast<uint32_t>(raw);
        float x;
        std::memcpy(&x, &bits, 4);
        v.f = x;
      } else {
        std::memcpy(&v.f, &raw, 8);
      }
  }
  return v;
}

}  // namespace

double MsgValue::Number() const {
  switch (kind) {
    case kBool:
    case kInt: return static_cast<double>(i);
    case kUint: return static_cast<double>(u);
    default: return f;
  }
}

const MsgValue* MsgValue::Field(const std::string& name) const {
  for (const auto& [n, v] : fields)
    if (n == name) return &v;
  return nullptr;
}

std::string MsgValue::FieldNames() const {
  std::string s;
  for (const auto& f : fields) s += (s.empty() ? "" : ", ") + ShownText(f.first);
  return s.empty() ? "none" : s;
}

Ros2MsgSchema::Ros2MsgSchema(const std::string& name, const std::string& text, const std::string& source) {
  CheckText(name, source, "a type name (text)");
  CheckText(text, source, "a ros2msg message definition (text)");
  // Split into definitions: lines of '=' separate them; each after the first opens with "MSG: name".
  std::vector<std::pair<std::string, int>> lines;  // text, 1-based line
  {
    size_t at = 0;
    for (int line = 1; at <= text.size(); ++line) {
      size_t end = text.find('\n', at);
      if (end == std::string::npos) end = text.size();
      lines.emplace_back(text.substr(at, end - at), line);
      at = end + 1;
    }
  }
  std::vector<std::vector<std::pair<std::string, int>>> blocks(1);
  std::vector<std::string> names = {Normalized(name)};
  for (size_t k = 0; k < lines.size(); ++k) {
    const std::string t = Trim(lines[k].first);
    if (t.size() >= 3 && t.find_first_not_of('=') == std::string::npos) {
      size_t m = k + 1;
      while (m < lines.size() && Trim(lines[m].first).empty()) ++m;
      const std::string head = m < lines.size() ? Trim(lines[m].first) : "";
      if (head.rfind("MSG:", 0) != 0)
        throw InputError(source + ": line " + std::to_string(m < lines.size() ? lines[m].second : lines[k].second) +
                         ": expected 'MSG: pkg/Type' after the separator line of '='");
      const std::string dep = Trim(head.substr(4));
      if (dep.empty() || dep.find_first_of(" \t") != std::string::npos)
        throw InputError(source + ": line " + std::to_string(lines[m].second) + ": 'MSG:' names no type");
      names.push_back(Normalized(dep));
      blocks.emplace_back();
      k = m;
      continue;
    }
    blocks.back().push_back(lines[k]);
  }
  // builtin_interfaces/Time and Duration (also ROS 1's time and duration) when the text lacks them.
  for (const char* b : {"builtin_interfaces/Time", "builtin_interfaces/Duration"}) {
    bool have = false;
    for (const std::string& n : names) have = have || n == b;
    if (!have) {
      names.push_back(b);
      blocks.push_back({{"int32 sec", 0}, {"uint32 nanosec", 0}});
    }
  }
  defs_.resize(blocks.size());
  std::vector<std::vector<std::pair<int, int>>> field_lines(blocks.size());  // per field: its line
  for (size_t d = 0; d < blocks.size(); ++d) {
    defs_[d].name = names[d];
    for (const auto& [raw, line] : blocks[d]) {
      const std::string at = source + ": line " + std::to_string(line) + " (" + names[d] + "): ";
      std::string t = raw;
      const size_t hash = t.find('#');
      const std::string head = Trim(hash == std::string::npos ? t : t.substr(0, hash));
      if (head.empty()) continue;
      const size_t sp = head.find_first_of(" \t");
      if (sp == std::string::npos) throw InputError(at + "'" + head + "': expected 'TYPE NAME'");
      std::string type = head.substr(0, sp);
      const std::string rest = Trim(head.substr(sp));
      size_t ne = 0;
      while (ne < rest.size() && (std::isalnum(static_cast<unsigned char>(rest[ne])) || rest[ne] == '_')) ++ne;
      const std::string fname = rest.substr(0, ne);
      if (Trim(rest.substr(ne)).rfind('=', 0) == 0) continue;  // a constant: NAME=VALUE
      if (!IsIdentifier(fname)) throw InputError(at + "'" + rest + "': expected a field name (letters, digits, _)");
      MsgField f;
      f.name = fname;
      // The array suffix: [N], [<=N], [].
      if (const size_t lb = type.find('['); lb != std::string::npos) {
        if (type.back() != ']') throw InputError(at + "'" + type + "': expected T[N], T[<=N] or T[]");
        const std::string inside = type.substr(lb + 1, type.size() - lb - 2);
        type = type.substr(0, lb);
        if (inside.empty()) {
          f.array = MsgField::kSequence;
        } else if (inside.rfind("<=", 0) == 0 && ParseCount(inside.substr(2), &f.array_size)) {
          f.array = MsgField::kBounded;
        } else if (ParseCount(inside, &f.array_size) && f.array_size > 0) {  // IDL: a positive size
          f.array = MsgField::kFixed;
        } else {
          throw InputError(at + "'" + inside + "': expected an array size N > 0, <=N or nothing");
        }
      }
      if (type.rfind("string<=", 0) == 0) {
        if (!ParseCount(type.substr(8), &f.string_bound) || f.string_bound == 0)
          throw InputError(at + "'" + type + "': expected string<=N, N a positive count");
        type = "string";
      }
      if (type == "wstring" || type.rfind("wstring<=", 0) == 0)
        throw InputError(at + "wstring is not decoded (its CDR encoding is implementation-defined), expected "
                              "string or another type");
      if (type == "time") type = "builtin_interfaces/Time";
      if (type == "duration") type = "builtin_interfaces/Duration";
      if (FindBuiltin(type)) {
        f.type = type;
      } else {
        // A message type: "pkg/Type", "pkg/msg/Type", or "Type" of this package (Header: std_msgs).
        std::string full = Normalized(type);
        if (full.find('/') == std::string::npos) {
          const std::string own = Package(names[d]) + "/" + full;
          full = full == "Header" && std::find(names.begin(), names.end(), own) == names.end() ? "std_msgs/Header"
                                                                                               : own;
        }
        const auto it = std::find(names.begin(), names.end(), full);
        if (it == names.end())
          throw InputError(at + "type '" + type + "' has no definition, expected a builtin (bool, byte, char, "
                                "int8 .. uint64, float32, float64, string) or a type of a MSG: block");
        f.type = full;
        f.message = static_cast<int>(it - names.begin());
      }
      defs_[d].fields.push_back(std::move(f));
    }
  }
  // A definition that contains itself (directly or not) has no finite encoding.
  std::vector<int> state(defs_.size(), 0);  // 0 new, 1 on the path, 2 done
  std::function<void(int)> visit = [&](int d) {
    state[d] = 1;
    for (const MsgField& f : defs_[d].fields) {
      if (f.message < 0) continue;
      if (state[f.message] == 1)
        throw InputError(source + ": " + defs_[d].name + " contains itself through field '" + f.name + "' (" +
                         f.type + "), expected definitions without cycles");
      if (state[f.message] == 0) visit(f.message);
    }
    state[d] = 2;
  };
  visit(0);
}

MsgValue Ros2MsgSchema::Decode(const std::string& bytes, const std::string& where) const {
  // The encapsulation (OMG DDS-XTypes 7.6.3.1.2): 0x00 0x00 CDR_BE, 0x00 0x01 CDR_LE; two option bytes.
  if (bytes.size() < 4)
    throw InputError(where + ": " + std::to_string(bytes.size()) + " bytes, expected a CDR message (4 bytes of "
                                 "encapsulation header at least)");
  if (bytes[0] != 0 || (bytes[1] != 0 && bytes[1] != 1)) {
    char b[64];
    std::snprintf(b, sizeof b, "0x%02X 0x%02X", static_cast<unsigned char>(bytes[0]),
                  static_cast<unsigned char>(bytes[1]));
    throw InputError(where + ": CDR encapsulation " + b + ", expected 0x00 0x01 (CDR little-endian) or 0x00 0x00 "
                                                           "(big-endian)");
  }
  CdrReader r(bytes, bytes[1] == 1, where);
  std::function<MsgValue(int, const std::string&, int)> message = [&](int d, const std::string& path, int depth) {
    if (depth > kMaxDepth) r.Fail(path, "nested deeper than " + std::to_string(kMaxDepth) + " messages");
    MsgValue v;
    v.kind = MsgValue::kStruct;
    const MsgDefinition& def = defs_[d];
    if (def.fields.empty()) {  // an empty definition is one uint8 in ROS 2's generated types
      r.Uint(1, path.empty() ? "(empty message)" : path);
      return v;
    }
    for (const MsgField& f : def.fields) {
      const std::string fp = path.empty() ? f.name : path + "." + f.name;
      const Builtin* b = f.message < 0 ? FindBuiltin(f.type) : nullptr;
      const auto one = [&](const std::string& p) {
        return b ? DecodeBuiltin(r, *b, f.string_bound, p) : message(f.message, p, depth + 1);
      };
      if (f.array == MsgField::kScalar) {
        v.fields.emplace_back(f.name, one(fp));
        continue;
      }
      uint64_t count = f.array_size;
      if (f.array != MsgField::kFixed) {
        count = r.Uint(4, fp);
        if (f.array == MsgField::kBounded && count > f.array_size)
          r.Fail(fp, std::to_string(count) + " elements, its type bounds it to " + std::to_string(f.array_size));
      }
      // Every element takes a byte at least: a count beyond the bytes left is a corrupt message.
      if (count > r.left())
        r.Fail(fp, std::to_string(count) + " elements, the message holds " + std::to_string(r.left()) + " more bytes");
      MsgValue a;
      a.kind = MsgValue::kArray;
      a.items.reserve(static_cast<size_t>(count));
      for (uint64_t k = 0; k < count; ++k) a.items.push_back(one(fp + "[" + std::to_string(k) + "]"));
      v.fields.emplace_back(f.name, std::move(a));
    }
    return v;
  };
  return message(0, "", 0);
}

MsgValue DecodeJsonMessage(const std::string& bytes, const std::string& where) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(bytes);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(where + ": not JSON (" + ShownText(e.what()) + "), expected a JSON object");
  }
  if (!j.is_object()) throw InputError(where + ": expected a JSON object, got " + j.type_name());
  std::function<MsgValue(const nlohmann::json&, int)> tree = [&](const nlohmann::json& x, int depth) {
    if (depth > kMaxDepth) throw InputError(where + ": nested deeper than " + std::to_string(kMaxDepth) + " levels");
    MsgValue v;
    switch (x.type()) {
      case nlohmann::json::value_t::object:
        v.kind = MsgValue::kStruct;
        for (const auto& [k, e] : x.items()) v.fields.emplace_back(k, tree(e, depth + 1));
        break;
      case nlohmann::json::value_t::array:
        v.kind = MsgValue::kArray;
        for (const auto& e : x) v.items.push_back(tree(e, depth + 1));
        break;
      case nlohmann::json::value_t::boolean: v.kind = MsgValue::kBool, v.i = x.get<bool>(); break;
      case nlohmann::json::value_t::number_integer: v.kind = MsgValue::kInt, v.i = x.get<int64_t>(); break;
      case nlohmann::json::value_t::number_unsigned: v.kind = MsgValue::kUint, v.u = x.get<uint64_t>(); break;
      case nlohmann::json::value_t::number_float: v.kind = MsgValue::kFloat, v.f = x.get<double>(); break;
      case nlohmann::json::value_t::string: v.kind = MsgValue::kString, v.s = x.get<std::string>(); break;
      default: break;
    }
    return v;
  };
  return tree(j, 0);
}

FieldPath ParseFieldPath(const std::string& text, const std::string& context) {
  FieldPath p;
  p.text = text;
  size_t at = 0;
  while (at <= text.size()) {
    FieldPath::Step s;
    size_t end = at;
    while (end < text.size() && text[end] != '.' && text[end] != '[') ++end;
    s.field = text.substr(at, end - at);
    if (s.field.empty())
      throw InputError(context + ": field path '" + text + "': an empty field name at character " +
                       std::to_string(at + 1) + ", expected FIELD.FIELD[INDEX]...");
    if (end < text.size() && text[end] == '[') {
      const size_t close = text.find(']', end);
      if (close == std::string::npos || close == end + 1)
        throw InputError(context + ": field path '" + text + "': expected [N] or [NAME] after '" + s.field + "'");
      s.indexed = true;
      s.key = text.substr(end + 1, close - end - 1);
      s.by_name = !ParseCount(s.key, &s.index);
      end = close + 1;
      if (end < text.size() && text[end] != '.')
        throw InputError(context + ": field path '" + text + "': expected '.' after ']' at character " +
                         std::to_string(end + 1));
    }
    p.steps.push_back(std::move(s));
    if (end >= text.size()) break;
    at = end + 1;
    if (at == text.size())
      throw InputError(context + ": field path '" + text + "' ends with '.', expected a field name after it");
  }
  return p;
}

const MsgValue& ResolveField(const MsgValue& msg, const FieldPath& path, const std::string& where) {
  const MsgValue* v = &msg;
  std::string so_far;
  for (const FieldPath::Step& s : path.steps) {
    const MsgValue* parent = v;
    v = parent->Field(s.field);
    if (!v)
      throw InputError(where + ": no field '" + s.field + "' in " + (so_far.empty() ? "the message" : so_far) +
                       " (its fields: " + parent->FieldNames() + ")");
    so_far += (so_far.empty() ? "" : ".") + s.field;
    if (!s.indexed) continue;
    if (v->kind != MsgValue::kArray) throw InputError(where + ": " + so_far + " is not an array, expected an array before [" + s.key + "]");
    uint64_t index = s.index;
    if (s.by_name) {
      // NAME's index in the `name` array beside this one (sensor_msgs/JointState: name, position, ...).
      const MsgValue* names = parent->Field("name");
      const std::string sibling = so_far.substr(0, so_far.size() - s.field.size()) + "name";
      if (!names || names->kind != MsgValue::kArray)
        throw InputError(where + ": " + so_far + "[" + s.key + "]: no array '" + sibling +
                         "' beside it to find the name in, expected [N] (an index) or a message with " + sibling);
      std::string have;
      index = names->items.size();
      for (size_t k = 0; k < names->items.size(); ++k) {
        const MsgValue& n = names->items[k];
        if (n.kind == MsgValue::kString && n.s == s.key && index == names->items.size()) index = k;
        have += (have.empty() ? "" : ", ") + (n.kind == MsgValue::kString ? ShownText(n.s) : std::string("?"));
      }
      if (index == names->items.size())
        throw InputError(where + ": name '" + s.key + "' is not in " + sibling + " [" + have + "]");
    }
    if (index >= v->items.size())
      throw InputError(where + ": " + so_far + "[" + s.key + "]: index " + std::to_string(index) + " beyond its " +
                       std::to_string(v->items.size()) + " elements");
    v = &v->items[static_cast<size_t>(index)];
    so_far += "[" + s.key + "]";
  }
  return *v;
}

}  // namespace exotwin
