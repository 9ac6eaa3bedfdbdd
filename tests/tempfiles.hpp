// Shared helpers of the tests that work with files: a temporary directory removed with what it
// holds, and whole files read and written as bytes. POSIX (mkdtemp).
#ifndef PRAY_TEMPFILES_HPP
#define PRAY_TEMPFILES_HPP

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace testkit {

// A fresh temporary directory, removed with everything in it at the end of the scope.
struct TempDir {
    std::string path;
    TempDir() {
        std::string t = (std::filesystem::temp_directory_path() / "pray_test_XXXXXX").string();
        std::vector<char> buf(t.begin(), t.end());
        buf.push_back(0);
        if (mkdtemp(buf.data())) path = buf.data();
    }
    ~TempDir() {
        std::error_code ec;
        if (!path.empty()) std::filesystem::remove_all(path, ec);
    }
    TempDir(const TempDir &) = delete;
    TempDir &operator=(const TempDir &) = delete;
    std::string operator/(const std::string &name) const { return path + "/" + name; }
    // The names of the files in the directory, sorted: "a b c".
    std::string listing() const {
        std::vector<std::string> names;
        for (const std::filesystem::directory_entry &e : std::filesystem::directory_iterator(path))
            names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        std::string s;
        for (size_t i = 0; i < names.size(); i++) s += (i ? " " : "") + names[i];
        return s;
    }
};

// The bytes of a file ("" when it cannot be read).
inline std::string slurp(const std::string &path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// Write the bytes to a file, replacing it.
inline void spit(const std::string &path, const std::string &bytes) {
    std::ofstream out(path, std::ios::binary);
    out << bytes;
}

} // namespace testkit

#endif
