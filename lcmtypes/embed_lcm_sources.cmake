# Writes a C++ file holding each .lcm file's text, so the runtime can derive wire layouts from the
# very files lcm-gen compiled (one source of truth, no hand-kept tables).
string(REPLACE "|" ";" files "${FILES}")
set(body "// Generated from lcmtypes/*.lcm by embed_lcm_sources.cmake. Do not edit.\n")
string(APPEND body "#include <string_view>\n#include <vector>\n\nnamespace semx::lcmtypes {\n")
string(APPEND body "struct LcmSource { std::string_view file; std::string_view text; };\n")
string(APPEND body "const std::vector<LcmSource>& lcm_sources() {\n  static const std::vector<LcmSource> s{\n")
foreach(f ${files})
  file(READ ${f} text)
  get_filename_component(name ${f} NAME)
  string(APPEND body "    {\"${name}\", R\"semxlcm(${text})semxlcm\"},\n")
endforeach()
string(APPEND body "  };\n  return s;\n}\n}  // namespace semx::lcmtypes\n")
file(WRITE ${OUT} "${body}")
