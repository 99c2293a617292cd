// One line for the person running the bench that is neither an error nor a
// finding: a board file in a deprecated form, say. Printed once per process
// on stderr ("avrbench: warning: ..."); a front end may take the lines
// instead (the Python module makes them Python warnings).
#pragma once

#include <functional>
#include <string>

namespace avrbench {

using NoticeSink = std::function<void(const std::string& line)>;

// Hands `line` to the sink, the first time it comes.
void notice(const std::string& line);
// Replaces the sink (an empty one restores stderr); returns the previous.
NoticeSink set_notice_sink(NoticeSink sink);

}  // namespace avrbench
