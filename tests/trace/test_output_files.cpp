// Output files: written whole or not at all, never removing what the bench
// did not create; JUnit that validates against its schema whatever the names;
// findings floods summarized.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "parts/HybridStepper.hpp"
#include "parts/StepDirDriver.hpp"
#include "core/Errors.hpp"
#include "core/Finding.hpp"
#include "core/OutputFile.hpp"
#include "support/Paths.hpp"
#include "support/RunCommand.hpp"
#include "trace/Junit.hpp"

namespace avrbench {
namespace {

namespace fs = std::filesystem;

std::size_t files_in(const fs::path& dir) {
    std::size_t n = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
    return n;
}

TEST(OutputFile, AnUncommittedWriteLeavesTheTargetAndNoTemporaryFile) {
    const auto dir = test::scratch_dir("outfile");
    const fs::path target = dir / "report.html";
    std::ofstream(target) << "previous run";
    {
        OutputFile out(target.string(), "HTML report");
        out.write("half of a new report");
        // no commit(): the writer failed part way
    }
    EXPECT_EQ(test::slurp(target), "previous run");
    EXPECT_EQ(files_in(dir), 1u);
    write_output_file(target.string(), "new report", "HTML report");
    EXPECT_EQ(test::slurp(target), "new report");
    EXPECT_EQ(files_in(dir), 1u);
}

TEST(OutputFile, RefusesFoldersAndMissingFolders) {
    const auto dir = test::scratch_dir("outfile-bad");
    EXPECT_THROW(check_output_path(dir.string(), "--vcd"), BadInput);
    EXPECT_THROW(check_output_path((dir / "no" / "x.vcd").string(), "--vcd"), BadInput);
    EXPECT_THROW(check_output_path("/dev/null", "--vcd"), BadInput);
    EXPECT_NO_THROW(check_output_path((dir / "x.vcd").string(), "--vcd"));
}

TEST(Junit, LongAndHostileNamesGiveXmlThatValidatesAgainstTheSchema) {
    const auto dir = test::scratch_dir("junit");
    std::vector<JunitCase> cases;
    JunitCase ok;
    ok.name = std::string(300, 'n');  // longer than any fixed buffer
    cases.push_back(ok);
    JunitCase failed;
    failed.name = "quotes \" <tags> & ampersands";
    failed.outcome = JunitCase::Outcome::Failed;
    failed.message = "line 1\nline 2 with \x01 control and \xff bad UTF-8";
    failed.text = "details ]]> <b> \t tab";
    cases.push_back(failed);
    JunitCase error;
    error.name = "caf\xc3\xa9";  // valid UTF-8 is kept
    error.outcome = JunitCase::Outcome::Error;
    error.message = "s.yaml:3: unknown key";
    cases.push_back(error);
    const std::string xml = junit_xml(cases, "avrbench");
    std::ofstream(dir / "j.xml") << xml;
    const auto r = test::run_command("xmllint --noout --schema " + test::source_path("tests/fixtures/junit.xsd") + " " +
                                         (dir / "j.xml").string(), dir);
    EXPECT_EQ(r.exit_code, 0) << r.err << xml;
    EXPECT_NE(xml.find("name=\"" + std::string(300, 'n') + "\""), std::string::npos);
    EXPECT_NE(xml.find("tests=\"3\" failures=\"1\" errors=\"1\""), std::string::npos);
    EXPECT_NE(xml.find("message=\"line 1&#10;line 2 with ? control and ? bad UTF-8\""), std::string::npos) << xml;
    EXPECT_NE(xml.find("caf\xc3\xa9"), std::string::npos);
}

TEST(Findings, AFloodIsSummarizedAsTheFirstFewThenACountPerKind) {
    std::vector<Finding> findings;
    for (int i = 0; i < 5000; ++i) {
        Finding f;
        f.kind = StepDirDriver::kStepHighTooShort;
        f.source = "x_driver";
        f.cycle = 16000u * static_cast<unsigned>(i);
        f.clock_hz = 16000000;
        f.has_pc = false;
        findings.push_back(f);
    }
    Finding stall;
    stall.kind = HybridStepper::kMotorStall;
    stall.source = "motor";
    stall.clock_hz = 16000000;
    stall.has_pc = false;
    findings.push_back(stall);
    const auto lines = summarize_findings(findings, 10);
    ASSERT_EQ(lines.size(), 11u);
    // Cycle 16000 at 16 MHz is 1 ms.
    EXPECT_EQ(lines[1], "x_driver: step-high-too-short at 0.001000 s (cycle 16000)");
    EXPECT_EQ(lines[10], "... and 4991 more: step-high-too-short (x_driver) x4990, motor-stall (motor) x1");
}

}  // namespace
}  // namespace avrbench
