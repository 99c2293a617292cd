// The tmc2130 part on the Einsy RAMBo's X driver pins, driven by our own
// firmware (firmware/boards/tmc2130_driver/main.c) the way the TMC2130
// datasheet (Rev. 1.09) describes: datagrams (§4.1), SPI mode and clock
// (§4.3), registers (§5), stallGuard2 (§8). Expected values from the
// datasheet's bit layouts and hand calculations beside them.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "boards/Board.hpp"
#include "boards/BoardFile.hpp"
#include "parts/Axis.hpp"
#include "parts/SpiBus.hpp"
#include "parts/Tmc2130.hpp"
#include "support/Paths.hpp"

namespace avrbench {
namespace {

// 100 steps/mm at 1/16 (Prusa MK3S X), 20 mm of travel, the carriage at 5 mm.
const char* kBoard = R"(
board: tmc2130-x
mcus:
  mega: {type: atmega2560, clock: 16MHz}
parts:
  x_driver: {type: tmc2130, microsteps: 16}
  x: {type: linear_axis, steps_per_mm: 100, travel: 20mm, start_position: 5mm}
nets:
  x_steps: [x_driver.steps, x.drive]
  x_load: [x.carriage, x_driver.load]
  x_step: [mega.PC0, x_driver.step]
  x_dir: [mega.PL0, x_driver.dir]
  x_enn: [mega.PA7, x_driver.enn]
  x_cs: [mega.PG0, x_driver.cs]
  sck: [mega.PB1, x_driver.sck]
  mosi: [mega.PB2, x_driver.mosi]
  miso: [mega.PB3, x_driver.miso]
  x_diag: [mega.PK2, x_driver.diag1]
)";

struct TmcRun {
    Board board;
    explicit TmcRun(const std::string& firmware, double seconds = 3, const std::string& board_text = kBoard)
        : board(parse_board_text(board_text, "tmc2130-x.yaml"), {{"mega", test::firmware(firmware)}}) {
        board.run_for_seconds(seconds);
        EXPECT_EQ(board.mcu().read_ram_u8("done"), 1);
    }
    std::uint32_t u32(const char* symbol) {
        const auto b = board.mcu().read_ram(symbol, 4);
        return b[0] | (b[1] << 8) | (b[2] << 16) | (static_cast<std::uint32_t>(b[3]) << 24);
    }
    Tmc2130& driver() { return dynamic_cast<Tmc2130&>(board.part("x_driver")); }
    Axis& axis() { return dynamic_cast<Axis&>(board.part("x")); }
    std::vector<std::string> finding_kinds() {
        std::vector<std::string> out;
        for (const auto& f : board.findings()) out.emplace_back(f.kind.name());
        return out;
    }
};

TEST(Tmc2130, AnswersDatagramsWithItsStatusAndTheLastReadsData) {
    TmcRun r("tmc2130_driver");
    // SPI_STATUS (§4.1.2): bit 0 reset_flag (GSTAT.reset, set at power-up),
    // bit 3 standstill (no STEP yet): 0x09. The first datagram asked for GSTAT.
    EXPECT_EQ(r.board.mcu().read_ram_u8("status_first"), 0x09);
    // The next datagram brings GSTAT's data: reset = bit 0 (§5.1).
    EXPECT_EQ(r.u32("gstat_read"), 0x00000001u);
    // The read cleared it (GSTAT is R+C): only standstill is left.
    EXPECT_EQ(r.board.mcu().read_ram_u8("status_after_gstat"), 0x08);
    // CHOPCONF is read-write: what was written (MRES 4, toff 3) comes back.
    EXPECT_EQ(r.u32("chopconf_read"), 0x04000003u);
    // IOIN (§5.1): VERSION 0x11 in bits 31:24, DRV_ENN (bit 4) high, DIR (bit 1)
    // high, STEP (bit 0) low at the time of the read.
    EXPECT_EQ(r.u32("ioin_read"), 0x11000012u);
    EXPECT_TRUE(r.board.findings().empty());
}

TEST(Tmc2130, StepsFollowMresAndDedge) {
    TmcRun r("tmc2130_driver");
    // 160 pulses at 1/16 = 10 full steps; 80 pulses with dedge = 160 edges =
    // 10 full steps; 10 pulses at MRES 8 (full steps) = 10 full steps. 30 full
    // steps at 16 microsteps and 100 (1/16) steps per mm: 30 * 16 / 100 =
    // 4.8 mm from 5 mm.
    EXPECT_NEAR(r.axis().position_mm(), 9.8, 1e-9);
    EXPECT_EQ(r.driver().steps_taken(), 160u + 160u + 10u);
    EXPECT_EQ(r.driver().position_256(), 30 * 256);
    EXPECT_EQ(r.driver().microsteps(), 1u);  // MRES 8 at the end
    // DRV_STATUS right after the moves: SG_RESULT 500 (sg_free at SGT 0, no
    // load), CS_ACTUAL = IRUN 16 in bits 20:16, no stall, not standstill
    // (2^20 clocks at 12 MHz = 87 ms have not passed).
    EXPECT_EQ(r.u32("drv_status_read"), 500u | (16u << 16));
}

TEST(Tmc2130, StepsBeforeToffIsSetAreAFindingAndDoNotMove) {
    TmcRun r("tmc2130_step_before_init");
    // CHOPCONF is 0 after power-up: toff = 0 disables the driver (§5.5).
    EXPECT_EQ(r.finding_kinds(), std::vector<std::string>{"tmc-step-while-off"});
    EXPECT_EQ(r.driver().steps_taken(), 330u);  // the 10 early pulses are not among them
    EXPECT_NEAR(r.axis().position_mm(), 9.8, 1e-9);
}

TEST(Tmc2130, StallGuardHomingStopsAtTheEndOfTravel) {
    TmcRun r("tmc2130_stall_home");
    // From 5 mm to 0 is 5 * 100 = 500 microsteps; the 501st finds the carriage
    // blocked: SG_RESULT 0, a stall (TSTEP about 47 <= TCOOLTHRS 1000), DIAG1
    // high (push-pull). The firmware counts full-step loops: 500 = 31 * 16 + 4,
    // so the stall comes in the 32nd.
    EXPECT_EQ(r.board.mcu().read_ram_u16("steps_to_stall"), 32);
    EXPECT_EQ(r.driver().steps_taken(), 501u);
    EXPECT_NEAR(r.axis().position_mm(), 0.0, 1e-9);
    EXPECT_TRUE(r.driver().stalled());
    // DRV_STATUS: stallGuard (bit 24), SG_RESULT 0, CS_ACTUAL = IRUN 16.
    EXPECT_EQ(r.u32("drv_status_read"), (1u << 24) | (16u << 16));
    // The blocked microstep pushed the carriage against its end: the axis says so.
    EXPECT_EQ(r.finding_kinds(), std::vector<std::string>{"axis-out-of-travel"});
}

// The same X axis homed sensorless against its frame: it may slip 4 full
// steps there (one electrical period), 4 * 16 microsteps / 100 steps/mm =
// 0.64 mm (the prusa-mk3s board's setting).
std::string board_with_stall_allowance() {
    std::string text = kBoard;
    const std::string axis = "start_position: 5mm}";
    text.replace(text.find(axis), axis.size(), "start_position: 5mm, stall_allowance: 0.64mm}");
    return text;
}

TEST(Tmc2130, AStallWithinTheAxisStallAllowanceIsNoCrash) {
    TmcRun r("tmc2130_stall_home", 3, board_with_stall_allowance());
    // As above: the 501st microstep pushes 0.01 mm into the end, within 0.64 mm.
    EXPECT_EQ(r.driver().steps_taken(), 501u);
    EXPECT_TRUE(r.driver().stalled());
    EXPECT_TRUE(r.board.findings().empty());
}

TEST(Tmc2130, AStallTheFirmwareMissesIsACrashPastTheStallAllowance) {
    TmcRun r("tmc2130_stall_home_sgt2", 4, board_with_stall_allowance());
    // 2000 full steps from 5 mm: 500 microsteps to the end, then 31 500 into
    // it; the 65th passes the 64 allowed (0.64 mm): 0.65 mm, reported once.
    EXPECT_EQ(r.driver().steps_taken(), 2000u * 16u);
    ASSERT_EQ(r.finding_kinds(), std::vector<std::string>{"axis-out-of-travel"});
    EXPECT_EQ(r.board.findings()[0].detail,
              "carriage driven 0.6500 mm into the lower end of travel (stall allowance 0.6400 mm)");
}

TEST(Tmc2130, AHigherSgtNeedsMoreLoadThanABlockedMotorGives) {
    TmcRun r("tmc2130_stall_home_sgt2", 4);
    // SGT +2 lifts the reading by 2 * 16 (the model's assumed step): a blocked
    // motor reads 32, never 0, so DIAG1 stays low and the firmware gives up
    // after its 2000 full steps.
    EXPECT_EQ(r.driver().sg_result(), 32);
    EXPECT_FALSE(r.driver().stalled());
    EXPECT_EQ(r.board.mcu().read_ram_u16("steps_to_stall"), 2000);
    EXPECT_EQ(r.driver().steps_taken(), 2000u * 16u);
}

TEST(Tmc2130, AMotorTunedToSgtTwoStallsAtSgtTwo) {
    // The motor reads 0 blocked at SGT +2 (its stall_sgt): the SGT +2
    // firmware now stops as the SGT 0 one did at stall_sgt 0 (501 steps, 32 loops).
    std::string text = kBoard;
    const std::string driver = "microsteps: 16}";
    text.replace(text.find(driver), driver.size(), "microsteps: 16, stall_sgt: 2}");
    TmcRun r("tmc2130_stall_home_sgt2", 3, text);
    EXPECT_EQ(r.driver().sg_result(), 0);
    EXPECT_TRUE(r.driver().stalled());
    EXPECT_EQ(r.board.mcu().read_ram_u16("steps_to_stall"), 32);
    EXPECT_EQ(r.driver().steps_taken(), 501u);
}

TEST(Tmc2130, TheWrongSpiModeAndAFastClockAreFindings) {
    TmcRun r("tmc2130_spi_mode0_fast");
    // Mode 0 at f/2 = 8 MHz: the TMC2130 shifts in mode 3 at up to 4 MHz (§4.3).
    EXPECT_EQ(r.finding_kinds(), (std::vector<std::string>{"spi-mode-mismatch", "spi-clock-too-fast"}));
}

TEST(Tmc2130, AnSpiPinOnTheWrongNetIsABoardError) {
    std::string text = kBoard;
    text.replace(text.find("mega.PB1"), 8, "mega.PB4");
    try {
        Board board(parse_board_text(text, "bad.yaml"), {{"mega", test::firmware("tmc2130_driver")}});
        FAIL() << "a TMC2130 whose sck is not on SCK was accepted";
    } catch (const BadInput& e) {
        EXPECT_NE(std::string(e.what()).find("must share a net with PB1"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace avrbench

namespace avrbench {
namespace {

TEST(PrusaMk3sBoard, HomesXSensorlessAgainstTheEndOfItsTravel) {
    // The standard board: X starts mid-travel at 127.5 mm, 100 steps/mm at
    // 1/16. The stall-homing firmware steps with DIR low, which on the MK3S
    // is X+ (INVERT_X_DIR 1): it drives X to its upper end, 255 mm - 127.5 mm
    // = 12750 microsteps away, and the 12751st finds it blocked. Its SGT 0 is
    // below the motor's tuned 3, so the blocked reading is 0 all the more:
    // stallGuard2 on DIAG1, the firmware stops.
    Board board(load_board_file("prusa-mk3s"), {{"mega", test::firmware("tmc2130_stall_home")}});
    board.run_for_seconds(2);
    ASSERT_EQ(board.mcu().read_ram_u8("done"), 1);
    auto& x = dynamic_cast<Tmc2130&>(board.part("x_driver"));
    EXPECT_EQ(x.steps_taken(), 12751u);
    EXPECT_TRUE(x.stalled());
    EXPECT_NEAR(dynamic_cast<Axis&>(board.part("x")).position_mm(), 255.0, 1e-9);
    EXPECT_TRUE(board.findings().empty());  // one microstep into the frame: within the stall allowance
    // 12750 = 796 * 16 + 14: the stall comes in the 797th full-step loop.
    EXPECT_EQ(board.mcu().read_ram_u16("steps_to_stall"), 797);
}

}  // namespace
}  // namespace avrbench
