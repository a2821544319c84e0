#include "semx/runtime/lcm_schema.hpp"

#include <algorithm>
#include <cctype>
#include <cstring>

namespace semx::lcmtypes {
struct LcmSource {
  std::string_view file;
  std::string_view text;
};
const std::vector<LcmSource>& lcm_sources();
}  // namespace semx::lcmtypes

namespace semx::runtime {

namespace {

struct Token {
  std::string text;
  int line;
};

std::vector<Token> tokenize(const std::string& file, const std::string& text) {
  std::vector<Token> out;
  int line = 1;
  std::size_t i = 0;
  const std::string punct = "{}[];,=";
  while (i < text.size()) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      ++i;
    } else if (std::isspace(static_cast<unsigned char>(c))) {
      ++i;
    } else if (c == '/' && i + 1 < text.size() && text[i + 1] == '/') {
      while (i < text.size() && text[i] != '\n') ++i;
    } else if (c == '/' && i + 1 < text.size() && text[i + 1] == '*') {
      const std::size_t end = text.find("*/", i + 2);
      if (end == std::string::npos)
        throw LcmSchemaError(file + ":" + std::to_string(line) + ": unterminated comment");
      line += static_cast<int>(std::count(text.begin() + i, text.begin() + end, '\n'));
      i = end + 2;
    } else if (punct.find(c) != std::string::npos) {
      out.push_back({std::string(1, c), line});
      ++i;
    } else {
      std::size_t j = i;
      while (j < text.size() && !std::isspace(static_cast<unsigned char>(text[j])) &&
             punct.find(text[j]) == std::string::npos && text.compare(j, 2, "//") != 0 &&
             text.compare(j, 2, "/*") != 0) {
        ++j;
      }
      out.push_back({text.substr(i, j - i), line});
      i = j;
    }
  }
  return out;
}

bool primitive_of(const std::string& t, LcmPrimitive& p) {
  static const std::pair<const char*, LcmPrimitive> table[] = {
      {"int8_t", LcmPrimitive::kInt8},   {"int16_t", LcmPrimitive::kInt16},
      {"int32_t", LcmPrimitive::kInt32}, {"int64_t", LcmPrimitive::kInt64},
      {"float", LcmPrimitive::kFloat},   {"double", LcmPrimitive::kDouble},
      {"string", LcmPrimitive::kString}, {"boolean", LcmPrimitive::kBoolean},
      {"byte", LcmPrimitive::kByte}};
  for (const auto& [name, prim] : table) {
    if (t == name) {
      p = prim;
      return true;
    }
  }
  return false;
}

// lcm-gen's hash (lcmgen.c): a rolling 64-bit hash of member names, primitive type names and
// dimensions. The arithmetic right shift and char truncation are part of the definition.
int64_t hash_update(int64_t v, char c) {
  return static_cast<int64_t>((static_cast<uint64_t>(v) << 8) ^ static_cast<uint64_t>(v >> 55)) + c;
}
int64_t hash_string(int64_t v, const std::string& s) {
  v = hash_update(v, static_cast<char>(s.size()));
  for (char c : s) v = hash_update(v, c);
  return v;
}

class Parser {
 public:
  Parser(std::string file, std::vector<Token> tokens) : file_(std::move(file)), tokens_(std::move(tokens)) {}

  void parse(std::map<std::string, LcmStruct>& out) {
    std::string package;
    while (i_ < tokens_.size()) {
      const std::string& t = next().text;
      if (t == "package") {
        package = next().text;
        expect(";");
      } else if (t == "struct") {
        LcmStruct s = parse_struct(package);
        const std::string full = s.full_name();
        if (out.count(full)) fail("struct '" + full + "' defined twice");
        out.emplace(full, std::move(s));
      } else {
        fail("expected 'package' or 'struct', found '" + t + "'");
      }
    }
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    const int line = tokens_.empty() ? 0 : tokens_[std::min(i_ ? i_ - 1 : 0, tokens_.size() - 1)].line;
    throw LcmSchemaError(file_ + ":" + std::to_string(line) + ": " + what);
  }
  const Token& next() {
    if (i_ >= tokens_.size()) fail("unexpected end of file");
    return tokens_[i_++];
  }
  const std::string& peek() const {
    static const std::string eof;
    return i_ < tokens_.size() ? tokens_[i_].text : eof;
  }
  void expect(const std::string& t) {
    if (next().text != t) fail("expected '" + t + "'");
  }

  LcmStruct parse_struct(const std::string& package) {
    LcmStruct s;
    s.package = package;
    s.name = next().text;
    s.file = file_;
    expect("{");
    while (peek() != "}") {
      if (peek() == "const") {
        next();
        next();  // type
        do {
          next();  // name
          expect("=");
          next();  // value
        } while (peek() == "," && next().text == ",");
        expect(";");
        continue;
      }
      LcmField f;
      f.type_name = next().text;
      f.name = next().text;
      if (!primitive_of(f.type_name, f.kind)) {
        f.kind = LcmPrimitive::kStruct;
        f.struct_name = f.type_name.find('.') == std::string::npos && !package.empty()
                            ? package + "." + f.type_name
                            : f.type_name;
      }
      while (peek() == "[") {
        next();
        LcmDimension d;
        const std::string size = next().text;
        if (!size.empty() && std::isdigit(static_cast<unsigned char>(size[0]))) {
          d.size = std::stoll(size);
        } else {
          d.variable = true;
          d.field = size;
          for (std::size_t k = 0; k < s.fields.size(); ++k) {
            if (s.fields[k].name == size) d.field_index = static_cast<int>(k);
          }
          if (d.field_index < 0 || !s.fields[d.field_index].dims.empty() ||
              !is_integer(s.fields[d.field_index].kind)) {
            fail("array size '" + size + "' of '" + f.name + "' is not an earlier integer field");
          }
        }
        f.dims.push_back(d);
        expect("]");
      }
      expect(";");
      s.fields.push_back(std::move(f));
    }
    expect("}");

    int64_t v = 0x12345678;
    for (const auto& f : s.fields) {
      v = hash_string(v, f.name);
      if (f.kind != LcmPrimitive::kStruct) v = hash_string(v, f.type_name);
      v = hash_update(v, static_cast<char>(f.dims.size()));
      for (const auto& d : f.dims) {
        v = hash_update(v, d.variable ? 1 : 0);
        v = hash_string(v, d.variable ? d.field : std::to_string(d.size));
      }
    }
    s.base_hash = v;
    return s;
  }

  std::string file_;
  std::vector<Token> tokens_;
  std::size_t i_ = 0;
};

}  // namespace

bool is_integer(LcmPrimitive p) {
  return p == LcmPrimitive::kInt8 || p == LcmPrimitive::kInt16 || p == LcmPrimitive::kInt32 ||
         p == LcmPrimitive::kInt64;
}

std::size_t primitive_size(LcmPrimitive p) {
  switch (p) {
    case LcmPrimitive::kInt8:
    case LcmPrimitive::kBoolean:
    case LcmPrimitive::kByte:
      return 1;
    case LcmPrimitive::kInt16:
      return 2;
    case LcmPrimitive::kInt32:
    case LcmPrimitive::kFloat:
      return 4;
    case LcmPrimitive::kInt64:
    case LcmPrimitive::kDouble:
      return 8;
    default:
      return 0;
  }
}

LcmSchema LcmSchema::parse(const std::vector<std::pair<std::string, std::string>>& files) {
  LcmSchema schema;
  for (const auto& [file, text] : files) {
    Parser(file, tokenize(file, text)).parse(schema.structs_);
  }
  schema.resolve();
  return schema;
}

void LcmSchema::resolve() {
  for (const auto& [name, s] : structs_) {
    for (const auto& f : s.fields) {
      if (f.kind == LcmPrimitive::kStruct && !structs_.count(f.struct_name)) {
        throw LcmSchemaError(s.file + ": field '" + f.name + "' has unknown type '" + f.type_name + "'");
      }
    }
  }
}

const LcmSchema& LcmSchema::semx() {
  static const LcmSchema schema = [] {
    std::vector<std::pair<std::string, std::string>> files;
    for (const auto& src : semx::lcmtypes::lcm_sources()) files.emplace_back(src.file, src.text);
    return parse(files);
  }();
  return schema;
}

const LcmStruct* LcmSchema::find(std::string_view name) const {
  auto it = structs_.find(std::string(name));
  if (it != structs_.end()) return &it->second;
  const LcmStruct* found = nullptr;
  for (const auto& [full, s] : structs_) {
    if (s.name == name) {
      if (found) return nullptr;  // ambiguous across packages
      found = &s;
    }
  }
  return found;
}

uint64_t LcmSchema::nested_hash(const LcmStruct& s, std::vector<const LcmStruct*>& parents) const {
  // Mirrors the generated _computeHash: recursion through nested types, a type already on the
  // stack contributes 0, and the sum is rotated left by one.
  if (std::find(parents.begin(), parents.end(), &s) != parents.end()) return 0;
  parents.push_back(&s);
  uint64_t hash = static_cast<uint64_t>(s.base_hash);
  for (const auto& f : s.fields) {
    if (f.kind == LcmPrimitive::kStruct) hash += nested_hash(structs_.at(f.struct_name), parents);
  }
  parents.pop_back();
  return (hash << 1) + ((hash >> 63) & 1);
}

int64_t LcmSchema::fingerprint(const LcmStruct& s) const {
  std::vector<const LcmStruct*> parents;
  return static_cast<int64_t>(nested_hash(s, parents));
}

std::size_t LcmSchema::min_encoded_size(const LcmStruct& s) const {
  std::size_t total = 0;
  for (const auto& f : s.fields) {
    std::size_t count = 1;
    for (const auto& d : f.dims) count = d.variable ? 0 : count * static_cast<std::size_t>(d.size);
    if (count == 0) continue;
    std::size_t each = primitive_size(f.kind);
    if (f.kind == LcmPrimitive::kString) each = 5;
    if (f.kind == LcmPrimitive::kStruct) each = min_encoded_size(structs_.at(f.struct_name));
    total += count * each;
  }
  return total;
}

}  // namespace semx::runtime
