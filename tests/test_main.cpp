// The test program's main: doctest from the system package, plus a closing line
// "N passed, M failed" (test cases) that CI reads.
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include <cstdio>

namespace {
unsigned g_passed, g_failed;

struct Summary : doctest::IReporter {
    explicit Summary(const doctest::ContextOptions &) {}
    void report_query(const doctest::QueryData &) override {}
    void test_run_start() override {}
    void test_run_end(const doctest::TestRunStats &s) override {
        g_passed = s.numTestCasesPassingFilters - s.numTestCasesFailed;
        g_failed = s.numTestCasesFailed;
    }
    void test_case_start(const doctest::TestCaseData &) override {}
    void test_case_reenter(const doctest::TestCaseData &) override {}
    void test_case_end(const doctest::CurrentTestCaseStats &) override {}
    void test_case_exception(const doctest::TestCaseException &) override {}
    void subcase_start(const doctest::SubcaseSignature &) override {}
    void subcase_end() override {}
    void log_assert(const doctest::AssertData &) override {}
    void log_message(const doctest::MessageData &) override {}
    void test_case_skipped(const doctest::TestCaseData &) override {}
};
} // namespace

DOCTEST_REGISTER_LISTENER("summary", 1, Summary);

int main(int argc, char **argv) {
    doctest::Context ctx;
    ctx.applyCommandLine(argc, argv);
    int rc = ctx.run();
    if (!ctx.shouldExit()) std::printf("%u passed, %u failed\n", g_passed, g_failed);
    return rc;
}
