#pragma once
// Parsing the JSON of a file the user gave (scene files, settings, glTF). Syntax errors,
// numbers beyond a double's range (1e999) and absurd nesting become an Error
// "file:line:column: /json/pointer: what" instead of a library exception that names
// neither the file nor the key.
#include <nlohmann/json.hpp>
#include <string>

namespace gilab {

// Also checks the parsed document's expected size against the memory budget. `kind`
// prefixes the problem in messages, e.g. "malformed glTF: ".
nlohmann::json parse_json_document(const std::string& text, const std::string& file, const std::string& kind = "");

// "/meshes/0/file" for nlohmann's ~ and / escapes.
std::string json_pointer_token(const std::string& key);

}  // namespace gilab
