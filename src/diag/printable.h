#pragma once
#include <cstddef>
#include <string>
#include <string_view>

namespace eamos::diag {

/// `text` as a message may quote it: a file, a sample or a command line can hold anything,
/// and a control byte echoed raw would garble the terminal or the log it goes to, a long value
/// bury the point of the message. Control bytes become '?', and past `max` bytes the text is
/// cut at a character boundary and ends in "...".
std::string printable(std::string_view text, std::size_t max = 40);

}  // namespace eamos::diag
