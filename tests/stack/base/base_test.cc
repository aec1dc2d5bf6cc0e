#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "stack/base/decimal.h"
#include "stack/base/files.h"
#include "stack/base/hash.h"
#include "stack/base/random.h"
#include "stack/base/status.h"
#include "stack/base/subprocess.h"
#include "tests/testing/temp_files.h"

namespace adse {
namespace {

namespace fs = std::filesystem;

TEST(StatusTest, ExitCodesSeparateBadInputFromFailures) {
  EXPECT_EQ(ExitCodeFor(Status::Ok()), 0);
  EXPECT_EQ(ExitCodeFor(Status::InvalidArgument("x")), 2);
  EXPECT_EQ(ExitCodeFor(Status::Corruption("x")), 2);
  EXPECT_EQ(ExitCodeFor(Status::IoError("x")), 1);
  EXPECT_EQ(Status::NotFound("f").WithContext("map").message(), "map: f");
}

TEST(DecimalTest, RoundsToSignificantDigitsAtEveryScale) {
  EXPECT_EQ(RoundToSignificantDigits(6 * 1.2, kDecimalDigits), 7.2);
  EXPECT_EQ(RoundToSignificantDigits(0.1 + 0.2, kDecimalDigits), 0.3);
  EXPECT_EQ(RoundToSignificantDigits(-14.700000000000001, kDecimalDigits),
            -14.7);
  EXPECT_EQ(RoundToSignificantDigits(1.23456789e-7, 3), 1.23e-7);
  // Past 10^digits the scale is a divisor: 10^-k is not exact, 10^k is.
  EXPECT_EQ(RoundToSignificantDigits(123456789012345.0, 3), 123e12);
  EXPECT_EQ(RoundToSignificantDigits(2.5, 1), 3.0);
  EXPECT_EQ(RoundToSignificantDigits(0.0, kDecimalDigits), 0.0);
  // At the ends of the double range the value is kept or rounded, never
  // lost to an overflowing scale.
  EXPECT_EQ(RoundToSignificantDigits(1e-300, kDecimalDigits), 1e-300);
  EXPECT_EQ(RoundToSignificantDigits(4.9e-324, kDecimalDigits), 4.9e-324);
  EXPECT_EQ(RoundToSignificantDigits(1.7e308, kDecimalDigits), 1.7e308);
  EXPECT_TRUE(std::isinf(RoundToSignificantDigits(INFINITY, 3)));
  EXPECT_TRUE(std::isnan(RoundToSignificantDigits(NAN, 3)));
}

TEST(HashTest, Sha256MatchesAKnownVectorAndPartsAreDelimited) {
  EXPECT_EQ(Sha256Hex("abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_NE(ContentHasher().Add("ab").Add("c").Hex(),
            ContentHasher().Add("a").Add("bc").Hex());
  EXPECT_EQ(ContentHasher().Add(0.1).Hex(), ContentHasher().Add(0.1).Hex());
  EXPECT_NE(ContentHasher().Add(0.1).Hex(),
            ContentHasher().Add(0.1000000001).Hex());
}

TEST(RandomTest, SameSeedSameStreamAndDerivedSeedsDiffer) {
  Random a(42), b(42), c(43);
  for (int i = 0; i < 100; ++i) {
    const double x = a.Uniform();
    EXPECT_EQ(x, b.Uniform());
    EXPECT_GE(x, 0.0);
    EXPECT_LT(x, 1.0);
  }
  EXPECT_NE(Random(42).NextU64(), c.NextU64());
  EXPECT_NE(Random::DeriveSeed(7, "lidar"), Random::DeriveSeed(7, "traffic"));
  // Mean and spread of the normal draw.
  Random n(1);
  double sum = 0, sum2 = 0;
  for (int i = 0; i < 20000; ++i) {
    const double x = n.Normal(1.0, 2.0);
    sum += x;
    sum2 += x * x;
  }
  EXPECT_NEAR(sum / 20000, 1.0, 0.05);
  EXPECT_NEAR(std::sqrt(sum2 / 20000 - (sum / 20000) * (sum / 20000)), 2.0,
              0.05);
}

TEST(FilesTest, AtomicWriteReplacesWholeAndLeavesNoTemporary) {
  const fs::path dir = adse::testing::TestScratch() / "adse_files_test";
  fs::remove_all(dir);
  const std::string path = (dir / "sub" / "f.txt").string();
  ASSERT_TRUE(WriteFileAtomic(path, "first").ok());
  ASSERT_TRUE(WriteFileAtomic(path, "second").ok());
  Result<std::string> text = ReadFile(path);
  ASSERT_TRUE(text.ok());
  EXPECT_EQ(*text, "second");
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir / "sub"))
    files += e.is_regular_file();
  EXPECT_EQ(files, 1);
  EXPECT_EQ(ReadFile((dir / "missing").string()).status().code(),
            Status::Code::kNotFound);
  EXPECT_EQ(ReadFile(path, 3).status().code(), Status::Code::kInvalidArgument);
}

// A pid no process has: a child's, once it has been reaped.
pid_t GonePid() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  ::waitpid(pid, nullptr, 0);
  return pid;
}

TEST(FilesTest, TemporariesOfWritersThatAreGoneAreRemovedOthersKept) {
  const fs::path dir = adse::testing::TestScratch() / "adse_abandoned_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  // "<path>.tmp.<host>.<pid>": this host's label from this process's name.
  const std::string own = TemporaryPathFor((dir / "out").string());
  const std::string stem = own.substr(0, own.rfind('.') + 1);
  const std::string gone = stem + std::to_string(GonePid());
  fs::create_directories(gone + "/scans");
  std::ofstream(gone + "/scans/a.pcd") << "x";
  std::ofstream(stem + std::to_string(GonePid())) << "a file";
  fs::create_directories(own);  // a live writer's: this process
  const std::string other_host =
      (dir / ("out.tmp.elsewhere." + std::to_string(GonePid()))).string();
  fs::create_directories(other_host);
  fs::create_directories(stem + "12ab");
  std::ofstream(dir / "out") << "the output";
  EXPECT_EQ(RemoveAbandonedTemporaries(dir.string()), 2);
  EXPECT_FALSE(fs::exists(gone));
  EXPECT_TRUE(fs::exists(own));
  EXPECT_TRUE(fs::exists(other_host));
  EXPECT_TRUE(fs::exists(stem + "12ab"));
  EXPECT_TRUE(fs::exists(dir / "out"));
  EXPECT_EQ(RemoveAbandonedTemporaries((dir / "missing").string()), 0);
  fs::remove_all(dir);
}

TEST(SubprocessTest, ExitStatusAndOutputTailAreReported) {
  Result<ProcessResult> ok = RunProcess({"sh", "-c", "echo hello"});
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(ok->exit_code, 0);
  EXPECT_EQ(ok->output, "hello\n");
  const Status failed = RunChecked({"sh", "-c", "echo broken map >&2; exit 3"});
  EXPECT_FALSE(failed.ok());
  EXPECT_NE(failed.message().find("exited with status 3"), std::string::npos);
  EXPECT_NE(failed.message().find("broken map"), std::string::npos);
  EXPECT_FALSE(RunProcess({"/nonexistent/program"}).ok());
}

}  // namespace
}  // namespace adse
