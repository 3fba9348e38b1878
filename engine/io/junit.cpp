// The JUnit XML report of `rm3d test --junit` (io/junit.h).
#include "io/junit.h"

#include <fstream>

namespace rm3d {

namespace {

/// Invalid UTF-8 bytes become U+FFFD, so the XML report stays well-formed.
std::string validUtf8(const std::string& s) {
  std::string o;
  for (size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    const size_t n = c < 0x80                        ? 1
                     : (c >> 5) == 0x6 && c >= 0xC2  ? 2
                     : (c >> 4) == 0xE               ? 3
                     : (c >> 3) == 0x1E && c <= 0xF4 ? 4
                                                     : 0;
    bool ok = n > 0 && i + n <= s.size();
    for (size_t k = 1; ok && k < n; ++k) ok = (static_cast<unsigned char>(s[i + k]) & 0xC0) == 0x80;
    if (ok && n == 3) {
      const unsigned char d = static_cast<unsigned char>(s[i + 1]);
      ok = !(c == 0xE0 && d < 0xA0) && !(c == 0xED && d >= 0xA0);  // overlong, surrogates
    }
    if (ok && n == 4) {
      const unsigned char d = static_cast<unsigned char>(s[i + 1]);
      ok = !(c == 0xF0 && d < 0x90) && !(c == 0xF4 && d >= 0x90);
    }
    if (ok) {
      o.append(s, i, n);
      i += n;
    } else {
      o += "\xEF\xBF\xBD";
      ++i;
    }
  }
  return o;
}

std::string xmlEscape(const std::string& raw) {
  const std::string s = validUtf8(raw);
  std::string o;
  for (char c : s) {
    switch (c) {
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '&':
        o += "&amp;";
        break;
      case '"':
        o += "&quot;";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20 && c != '\n' && c != '\t')
          o += ' ';
        else
          o += c;
    }
  }
  return o;
}

}  // namespace

bool writeJunit(const std::string& path, const std::vector<TestOutcome>& outcomes) {
  std::ofstream f(path);
  int failures = 0;
  double total = 0;
  for (const TestOutcome& o : outcomes) {
    failures += o.passed ? 0 : 1;
    total += o.seconds;
  }
  f << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  f << "<testsuites><testsuite name=\"rm3d\" tests=\"" << outcomes.size() << "\" failures=\"" << failures
    << "\" time=\"" << total << "\">\n";
  for (const TestOutcome& o : outcomes) {
    f << "  <testcase classname=\"worlds\" name=\"" << xmlEscape(o.file) << "\" time=\"" << o.seconds << "\"";
    if (o.passed) {
      f << "/>\n";
    } else {
      f << "><failure message=\"" << xmlEscape(o.message.substr(0, o.message.find('\n'))) << "\">"
        << xmlEscape(o.message) << "</failure></testcase>\n";
    }
  }
  f << "</testsuite></testsuites>\n";
  f.close();
  return bool(f);
}

}  // namespace rm3d
