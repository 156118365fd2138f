#include "kfd/pipeline/error.h"

namespace kfd {

std::string plainMessage(const std::string& what) {
    static const std::string kBanner = "==== MRPT exception ====";
    const auto banner = what.find(kBanner);
    if (banner == std::string::npos) return what;
    const auto msg = what.rfind("Message:");  // the innermost of nested banners
    if (msg == std::string::npos || msg < banner) return what.substr(0, what.find('\n'));
    auto end = what.find("\nLocation:", msg);
    if (end == std::string::npos) end = what.size();
    std::string out = what.substr(0, banner), joined;
    std::size_t pos = msg + 8;
    while (pos < end) {
        std::size_t eol = what.find('\n', pos);
        if (eol == std::string::npos || eol > end) eol = end;
        const auto b = what.find_first_not_of(" \t\r", pos);
        if (b < eol) {
            auto e = what.find_last_not_of(" \t\r", eol - 1);
            if (!joined.empty()) joined += "; ";
            joined += what.substr(b, e - b + 1);
        }
        pos = eol + 1;
    }
    return out + (joined.empty() ? "MRPT exception without a message" : joined);
}

}  // namespace kfd
