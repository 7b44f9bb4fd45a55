// Text put into an HTML page (the batch report, the visitor's page): the five characters HTML gives a meaning,
// as entities, so that a file name or a message can never become markup.
#pragma once

#include <string>

namespace avatarbooth {

std::string escapeHtml(const std::string& text);

}  // namespace avatarbooth
