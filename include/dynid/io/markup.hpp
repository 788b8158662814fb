#pragma once

#include <string>

namespace dynid {

/// `text` with &, <, > and " written as entities, for XML or HTML element text and double-quoted
/// attribute values (the URDF writer's names, the HTML report's title): names come from the
/// input, and a raw '"' or '<' would end the attribute or start a tag. No throw.
std::string markup_escaped(const std::string& text);

}  // namespace dynid
