#pragma once
// One open mission as the editor last sent it, checked by the same stages as `eamos check`
// (parse, check, graphs and their static checks), kept with what the editor features
// need: the AST, partial when the text does not parse, and the tokens with their places.
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "diag/diagnostics.h"
#include "fleet/fleet.h"
#include "lang/ast.h"
#include "lang/token.h"
#include "lsp/text.h"

namespace eamos::lsp {

struct Token {
  lang::TokenKind kind = lang::TokenKind::end_of_file;
  SourceLocation loc;
  int length = 0;  ///< bytes; a token never spans lines
  std::string text;
};

struct Document {
  std::string uri;
  std::string path;  ///< the file the URI names; the URI itself for a buffer in no file
  long long version = 0;
  std::shared_ptr<SourceFile> source;
  lang::Mission mission;
  std::vector<Token> tokens;  ///< in order; no semicolon the lexer inserted at a newline
};

/// An error or warning with the notes that belong to it ("first defined here"), each with its
/// own place, which may be in the other file. A note that belongs to nothing stands alone.
struct Published {
  Diagnostic diagnostic;
  std::vector<Diagnostic> notes;
};

/// What one check found, split by the file each error or warning is about.
struct CheckResult {
  std::vector<Published> mission;  ///< the document's, and those tied to no file
  std::vector<Published> fleet;    ///< the fleet file's
};

/// Gives the document `text` and checks it as `eamos check [--fleet fleet_path]` does,
/// reading the fleet file afresh (an edit to it counts at the next check). `fleet` gets the
/// fleet the document was checked against, for hover and completion.
CheckResult update(Document& doc, std::string text, const std::string& fleet_path, fleet::Fleet& fleet);

/// How the diagnostics of one file are published. A note goes into its diagnostic's
/// relatedInformation (at `uri_of` its file) when the client shows those; otherwise a note in
/// the same file is published beside it as information, and one elsewhere ends its message.
struct PublishOptions {
  Encoding encoding = Encoding::utf16;
  bool related_information = false;
  std::function<std::string(const Diagnostic&)> uri_of;
};

/// The protocol's Diagnostic[] for diagnostics all about one file.
nlohmann::json diagnostics_json(const std::vector<Published>& items, const PublishOptions& options);

/// The source line (1-based) of the document; empty past the end.
std::string_view line_of(const Document& doc, int line);
/// The protocol's range of a token.
Range token_range(const Document& doc, const Token& t, Encoding enc);

}  // namespace eamos::lsp
