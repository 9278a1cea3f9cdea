#pragma once
// Text into XML, SVG and HTML (and Graphviz's HTML-like labels): every picture and page the
// project writes escapes names and labels the same way, since they come from user files.
#include <string>
#include <string_view>

namespace eamos::diag {

/// `text` with & < > " ' as character references, safe in element content and in either
/// kind of quoted attribute. The apostrophe is written `&#39;`: Graphviz knows no `&apos;`.
std::string xml_escape(std::string_view text);

}  // namespace eamos::diag
