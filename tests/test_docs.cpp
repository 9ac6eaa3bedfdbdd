// The documentation's PRAY programs run: every block fenced as ```pray in README.md and
// docs/pray-language.md is a whole program, and runs without an error (at 8 x 8 pixels, frames
// kept in memory). Blocks fenced without a language are fragments, templates or output.
#include <doctest/doctest.h>

#include "testkit.hpp"

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {
struct Block {
    int line;  // of the opening fence
    std::string text;
};

std::vector<Block> pray_blocks(const std::string &path) {
    std::ifstream in(path.c_str());
    std::vector<Block> out;
    std::string l;
    int n = 0;
    bool inside = false, keep = false;
    Block b;
    while (std::getline(in, l)) {
        n++;
        if (l.compare(0, 3, "```") == 0) {
            if (inside && keep) out.push_back(b);
            if (!inside) {
                keep = l == "```pray";
                b.line = n;
                b.text.clear();
            }
            inside = !inside;
        } else if (inside) {
            b.text += l + "\n";
        }
    }
    return out;
}
} // namespace

TEST_CASE("documentation: every ```pray block of the README and the language manual runs") {
    struct Doc {
        const char *path;
        size_t at_least;  // so that a file moved or a fence renamed is noticed
    } docs[] = {{"README.md", 1}, {"docs/pray-language.md", 20}};
    for (const Doc &d : docs) {
        std::vector<Block> blocks = pray_blocks(d.path);
        CAPTURE(d.path);
        CHECK(blocks.size() >= d.at_least);
        for (const Block &b : blocks) {
            testkit::Result r = testkit::run(b.text, {"width=8", "height=8"}, "doc.ray");
            CHECK_MESSAGE(r.status == PRAY_OK, d.path, ":", b.line, ": ", r.error);
        }
    }
}
