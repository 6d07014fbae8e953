// The browser client end to end in headless Chromium (Debian's `chromium`), driven through its DevTools
// protocol by a Python script on python3-websockets: the page loads and connects, frames arrive and are
// drawn, a click with "aim" ticked points the dryer at the surface under the pointer (the dryer's
// direction changes in the stats) and the simulation runs on; in a scene with a tap, the tap panel closes
// and opens it (what has been poured stops and starts growing). Screenshots are saved as artefacts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>

#include "tests/server/serve_support.h"

namespace thaw {
namespace {

using testing::CommandResult;
using testing::run_thaw;
using testing::ServedScene;
using testing::TempDir;

// A Python program that starts headless Chromium, opens the served page and runs `scenario`: Python
// source defining `async def scenario(call, js, until)`, where call(method, **params) is a DevTools
// command, js(expr) evaluates in the page and until(expr, seconds) waits for it to be truthy.
std::string in_chromium(const std::string& scenario) {
  return R"py(
import asyncio, base64, json, os, re, socket, subprocess, tempfile, time, urllib.request, websockets
s = socket.socket(); s.bind(("127.0.0.1", 0)); DEVTOOLS = s.getsockname()[1]; s.close()
profile = tempfile.mkdtemp(dir=".")
chrome = subprocess.Popen(["/usr/bin/chromium", "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic",
                           "--no-first-run", "--disable-background-networking", "--disable-component-update",
                           "--disable-sync", f"--user-data-dir={profile}", f"--remote-debugging-port={DEVTOOLS}",
                           "--remote-debugging-address=127.0.0.1", "--window-size=1100,700", "about:blank"],
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
)py" + scenario +
         R"py(
try:
    for _ in range(100):
        try:
            pages = json.load(urllib.request.urlopen(f"http://127.0.0.1:{DEVTOOLS}/json", timeout=1))
            page = [p for p in pages if p["type"] == "page"][0]
            break
        except Exception:
            time.sleep(0.2)
    async def main():
        async with websockets.connect(page["webSocketDebuggerUrl"], max_size=None) as cdp:
            ids = iter(range(1, 10**6))
            async def call(method, **params):
                i = next(ids)
                await cdp.send(json.dumps({"id": i, "method": method, "params": params}))
                while True:
                    m = json.loads(await asyncio.wait_for(cdp.recv(), 30))
                    if m.get("id") == i:
                        return m.get("result", {})
            async def js(expr):
                r = await call("Runtime.evaluate", expression=expr, returnByValue=True)
                return r.get("result", {}).get("value")
            async def until(expr, seconds):
                t0 = time.time()
                while time.time() - t0 < seconds:
                    v = await js(expr)
                    if v:
                        return v
                    await asyncio.sleep(0.2)
                return None
            await call("Page.enable")
            await call("Page.navigate", url=f"http://127.0.0.1:{PORT}/")
            print("connected", await until("document.getElementById('connection').textContent === 'connected'", 30))
            await scenario(call, js, until)
            shot = await call("Page.captureScreenshot", format="png")
            with open("browser.png", "wb") as f:
                f.write(base64.b64decode(shot["data"]))
            print("screenshot", os.path.getsize("browser.png") > 10000)
    asyncio.run(main())
finally:
    chrome.kill()
)py";
}

void expect_lines(const std::string& out, std::initializer_list<const char*> lines) {
  for (const char* line : lines) EXPECT_NE(out.find(line), std::string::npos) << line << "\n" << out;
}

// THAW_TEST_SCREENSHOTS=DIR keeps a test's page as DIR/name, to be looked at; without it the page goes with
// the test's folder.
void keep_screenshot(const TempDir& dir, const std::string& name) {
  if (const char* keep = std::getenv("THAW_TEST_SCREENSHOTS"))
    std::filesystem::copy_file(dir.path() / "browser.png", std::filesystem::path(keep) / name,
                               std::filesystem::copy_options::overwrite_existing);
}

TEST(BrowserClient, LoadsStreamsAndAimsADryerInHeadlessChromium) {
  // scripts/debian-packages.txt lists chromium, so scripts/setup installs it: its absence is a broken
  // set-up, not a reason to pass.
  ASSERT_TRUE(std::filesystem::exists("/usr/bin/chromium"))
      << "Debian's chromium is not installed (scripts/setup)";
  TempDir dir("browser");
  ServedScene served(dir, "default --state-dir states");
  ASSERT_GT(served.port(), 0) << served.log();
  int status = 0;
  const std::string out = served.run_python(in_chromium(R"py(
async def scenario(call, js, until):
    print("frames", bool(await until("framesSeen > 0 || fps > 0", 30)))
    print("stats", bool(await until("document.getElementById('hud').textContent.includes('ice')", 30)))
    # The canvas shows the picture, not a blank: many distinct colours in its middle.
    colours = await js("""(() => { const c = document.getElementById('view');
        const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data; const s = new Set();
        for (let i = 0; i < d.length; i += 4 * 97) s.add(d[i] + ',' + d[i + 1] + ',' + d[i + 2]);
        return s.size; })()""")
    print("colours", colours > 20)
    print("no taps", await js("document.getElementById('taps').hidden"))
    before = await js("JSON.stringify(dryers[0].direction)")
    await js("document.getElementById('aim').click()")
    box = await js("(() => { const r = document.getElementById('view').getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; })()")
    x, y = box[0] + 0.40 * box[2], box[1] + 0.42 * box[3]
    for kind in ("mousePressed", "mouseReleased"):
        await call("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left", clickCount=1)
    aimed = await until(f"JSON.stringify(dryers[0].direction) !== {json.dumps(before)}", 20)
    print("aimed", bool(aimed))
    # The simulation goes on under the new aim (the melt itself is the smoke test's business).
    t_aim = await js("history.length ? history[history.length - 1][0] : 0")
    print("running", bool(await until(f"history.length && history[history.length - 1][0] > {t_aim}", 60)))
)py"),
                                            240, &status);
  EXPECT_EQ(status, 0) << out;
  expect_lines(out, {"connected True", "frames True", "stats True", "colours True", "no taps True",
                     "aimed True", "running True", "screenshot True"});
  std::printf("[ info ] screenshot: %s\n", (dir.path() / "browser.png").c_str());
  EXPECT_TRUE(served.stop()) << served.log();
}

// The tap panel of a scene with an emitter: it shows, closing the tap stops what is poured from growing
// while the simulation runs on, and opening it again pours more.
TEST(BrowserClient, TheTapPanelClosesAndOpensAnEmitter) {
  ASSERT_TRUE(std::filesystem::exists("/usr/bin/chromium"))
      << "Debian's chromium is not installed (scripts/setup)";
  TempDir dir("browser-tap");
  ServedScene served(dir, "pour-into-glass --set spacing=0.005 --state-dir states");
  ASSERT_GT(served.port(), 0) << served.log();
  int status = 0;
  const std::string out = served.run_python(in_chromium(R"py(
POURED = "(() => { const m = document.getElementById('hud').textContent.match(/poured ([0-9.]+) g/); return m ? Number(m[1]) : 0; })()"
SIM_TIME = "(history.length ? history[history.length - 1][0] : 0)"
async def scenario(call, js, until):
    print("taps shown", await until("!document.getElementById('taps').hidden && emitters.length === 1", 30))
    print("pouring", bool(await until(f"{POURED} > 0", 60)))
    await js("document.getElementById('emitter-open').click()")
    print("closed", bool(await until("emitters[0].open === false", 20)))
    closed = await js(POURED)
    t_closed = await js(SIM_TIME)
    print("ran on", bool(await until(f"{SIM_TIME} > {t_closed} + 0.02", 60)))
    print("held", await js(POURED) == closed)
    await js("document.getElementById('emitter-open').click()")
    print("opened", bool(await until("emitters[0].open === true", 20)))
    print("pours again", bool(await until(f"{POURED} > {closed}", 60)))
)py"),
                                            240, &status);
  EXPECT_EQ(status, 0) << out;
  expect_lines(out, {"connected True", "taps shown True", "pouring True", "closed True", "ran on True",
                     "held True", "opened True", "pours again True", "screenshot True"});
  std::printf("[ info ] screenshot: %s\n", (dir.path() / "browser.png").c_str());
  EXPECT_TRUE(served.stop()) << served.log();
}

// The Substances panel (issue 20): in salt-on-ice it lists the scene's substances; with "drop" ticked, a
// click on the ice drops the chosen dose of salt there (the salt's inflow in the stats grows by it); the
// Colour menu offers each substance, and choosing one colours the particle view by it.
TEST(BrowserClient, TheSubstancesPanelDropsSaltWhereTheClickIs) {
  ASSERT_TRUE(std::filesystem::exists("/usr/bin/chromium"))
      << "Debian's chromium is not installed (scripts/setup)";
  TempDir dir("browser-substances");
  ServedScene served(dir, "salt-on-ice --set spacing=0.004 --state-dir states");
  ASSERT_GT(served.port(), 0) << served.log();
  int status = 0;
  const std::string out = served.run_python(in_chromium(R"py(
async def scenario(call, js, until):
    print("panel", await until("!document.getElementById('substances').hidden && substances.length === 2", 30))
    print("frames", bool(await until("framesSeen > 0 || fps > 0", 30)))
    print("books", bool(await until("substanceBooks.salt && substanceBooks.salt.total > 0", 30)))
    await js("{ const a = document.getElementById('substance-amount'); a.value = '0.001'; }")
    await js("document.getElementById('drop').click()")
    box = await js("(() => { const r = document.getElementById('view').getBoundingClientRect(); return [r.left, r.top, r.width, r.height]; })()")
    x, y = box[0] + 0.5 * box[2], box[1] + 0.55 * box[3]
    for kind in ("mousePressed", "mouseReleased"):
        await call("Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left", clickCount=1)
    print("dropped", bool(await until("substanceBooks.salt && Math.abs(substanceBooks.salt.inflow - 0.001) < 1e-12", 30)))
    print("closed", await js("Math.abs(substanceBooks.salt.closure_relative) < 1e-12"))
    # 1 g on a few grams of ice at -5 °C: more than its melt dissolves, and the panel says how much is left.
    print("undissolved", await until("document.getElementById('substance-total').textContent.includes('undissolved')", 20))
    print("line", await js("document.getElementById('substance-total').textContent"))
    print("menu", await js("[...document.getElementById('colour-by').options].map(o => o.value).join(',')"))
    await js("{ document.getElementById('view-kind').value = 'particles'; document.getElementById('colour-by').value = 'substance:salt'; document.getElementById('colour-by').dispatchEvent(new Event('change')); }")
    print("coloured", bool(await until("document.getElementById('colour-by').value === 'substance:salt' && document.getElementById('message').textContent === ''", 20)))
)py"),
                                            240, &status);
  EXPECT_EQ(status, 0) << out;
  expect_lines(
      out, {"connected True", "panel True", "frames True", "books True", "dropped True", "closed True",
            "undissolved True", "menu phase,temperature,speed,substance:salt,substance:dye", "coloured True",
            "screenshot True"});
  keep_screenshot(dir, "browser-salt.png");
  EXPECT_TRUE(served.stop()) << served.log();
}

// The Substances panel says where a coating is (issue 20): in wash-the-plate, with the grease chosen, its
// line counts what sticks to the plate; with the detergent chosen, what sits on the water's surface.
TEST(BrowserClient, TheSubstancesPanelSaysWhatSticksToSolids) {
  ASSERT_TRUE(std::filesystem::exists("/usr/bin/chromium"))
      << "Debian's chromium is not installed (scripts/setup)";
  TempDir dir("browser-coating");
  ServedScene served(dir, "wash-the-plate --set spacing=0.005 --state-dir states");
  ASSERT_GT(served.port(), 0) << served.log();
  int status = 0;
  const std::string out = served.run_python(in_chromium(R"py(
TOTAL = "document.getElementById('substance-total').textContent"
async def scenario(call, js, until):
    print("panel", await until("!document.getElementById('substances').hidden && substances.length === 2", 30))
    print("books", bool(await until("substanceBooks.grease && substanceBooks.grease.on_solids > 0", 30)))
    await js("{ const s = document.getElementById('substance'); s.value = 'grease'; s.dispatchEvent(new Event('change')); }")
    print("on solids", bool(await until(f"/[0-9.]+ (g|mg|µg) on solids and ice/.test({TOTAL}) && !/e-/.test({TOTAL})", 20)))
    print("[ info ] " + await js(TOTAL))
    await js("{ const s = document.getElementById('substance'); s.value = 'detergent'; s.dispatchEvent(new Event('change')); }")
    print("on surface", bool(await until(f"/[0-9.]+ (g|mg|µg) on the surface/.test({TOTAL}) && !/on solids/.test({TOTAL}) && !/e-/.test({TOTAL})", 20)))
    print("[ info ] " + await js(TOTAL))
    # The surface view coloured by the grease (the scene's #9c6b1c, shown in the menu) stains the plate.
    print("swatch", await js("document.querySelector('#colour-by option[value=\"substance:grease\"]').style.color"))
    await js("{ document.getElementById('view-kind').value = 'surface'; document.getElementById('colour-by').value = 'substance:grease'; document.getElementById('colour-by').dispatchEvent(new Event('change')); }")
    print("tinted", bool(await until("document.getElementById('view-kind').value === 'surface' && document.getElementById('colour-by').value === 'substance:grease' && document.getElementById('message').textContent === '' && framesSeen > 0", 20)))
    # Full colour at 10 g/L: the server keeps it, so the stats that follow leave the menu there.
    await js("{ const t = document.getElementById('tint-reference'); t.value = '10'; t.dispatchEvent(new Event('change')); t.blur(); window.statsBefore = history.length; }")
    print("reference", bool(await until("history.length > window.statsBefore + 2 && document.getElementById('tint-reference').value === '10' && document.getElementById('message').textContent === ''", 20)))
)py"),
                                            240, &status);
  EXPECT_EQ(status, 0) << out;
  expect_lines(out, {"connected True", "panel True", "books True", "on solids True", "on surface True",
                     "swatch rgb(156, 107, 28)", "tinted True", "reference True", "screenshot True"});
  keep_screenshot(dir, "browser-coating.png");
  for (std::size_t at = out.find("[ info ]"); at != std::string::npos; at = out.find("[ info ]", at + 1))
    std::printf("%s\n", out.substr(at, out.find('\n', at) - at).c_str());
  EXPECT_TRUE(served.stop()) << served.log();
}

// An air scene's page (issue 18): the readout says how much air there is and how warm (the dryer's jet
// shows in the air's top temperature), and calls what comes in and goes out what it is, air, not water
// poured; the readout's lines stay within the picture.
TEST(BrowserClient, AnAirScenesReadoutShowsItsAir) {
  ASSERT_TRUE(std::filesystem::exists("/usr/bin/chromium"))
      << "Debian's chromium is not installed (scripts/setup)";
  TempDir dir("browser-air");
  ServedScene served(dir, "ice-air-dryer --state-dir states");
  ASSERT_GT(served.port(), 0) << served.log();
  int status = 0;
  const std::string out = served.run_python(in_chromium(R"py(
HUD = "document.getElementById('hud').textContent"
async def scenario(call, js, until):
    print("air counted", bool(await until(f"/particles 0 water, 216 ice, 11724 air/.test({HUD})", 60)))
    warm = await until(f"(() => {{ const m = {HUD}.match(/air mean [-0-9.]+ °C, [-0-9.]+ to ([-0-9.]+) °C/); return m && Number(m[1]) > 40 ? Number(m[1]) : null; }})()", 90)
    print("[ info ] the air's warmest", warm, "°C")
    print("jet warm", bool(warm))
    print("books named", bool(await until(f"/came in [0-9.]+ g/.test({HUD}) && !/poured/.test({HUD})", 60)))
    fits = await js("(() => { const h = document.getElementById('hud'); return h.scrollWidth <= h.clientWidth + 1 && h.getBoundingClientRect().right <= document.getElementById('view').getBoundingClientRect().right + 1; })()")
    print("fits", fits)
)py"),
                                            240, &status);
  EXPECT_EQ(status, 0) << out;
  expect_lines(out, {"connected True", "air counted True", "jet warm True", "books named True", "fits True",
                     "screenshot True"});
  EXPECT_TRUE(served.stop()) << served.log();
}

// A watchable pace (issue 16): in the default scene as it ships, with its dryer on, the ice the page
// shows loses at least 10 % of its mass within 60 s of wall time on a machine as fast as the one the pace
// was set on, while the water moves; the page says how fast time runs and the heat factor; the picture
// where the ice was changes. Screenshots at the start and at 10 % are saved.
//
// The 60 s hold where the hand-written density loop of `thaw bench throughput` (the same loop on every
// build, measured in this run, under this run's load) takes kPaceMachineUs per particle-step at 24k
// particles; a slower machine gets proportionally longer. The machines this runs on differ by 2x: the
// same build reached 10 % in 37 s on one (the loop 0.07 us) and 57-66 s on another (0.137-0.160 us),
// and a CI machine of the second kind missed a fixed 60 s by 8 % of the ice (0.0039 simulated s a second).
// THAW_TEST_TIME_SCALE stretches the limit further.
constexpr double kPaceMachineUs = 0.08;

// The hand-written reference density loop's time on this machine now [us per particle-step], or 0 when
// the bench did not run.
double reference_loop_us(const TempDir& dir) {
  const CommandResult r = run_thaw("bench throughput --sizes 24000 --json", dir);
  if (!r.exited || r.exit_code != 0) return 0.0;
  try {
    return Json::parse(r.out).at("sizes").at(0).at("reference_density_us").get<double>();
  } catch (const std::exception&) {
    return 0.0;
  }
}

TEST(BrowserClient, TheDefaultSceneVisiblyMeltsWithinAMinute) {
  ASSERT_TRUE(std::filesystem::exists("/usr/bin/chromium"))
      << "Debian's chromium is not installed (scripts/setup)";
  TempDir dir("browser-melt");
  const double loop_us = reference_loop_us(dir);
  ASSERT_GT(loop_us, 0.0) << "thaw bench throughput gave no reference loop time";
  const double machine = std::max(1.0, loop_us / kPaceMachineUs);
  std::printf("[ info ] reference loop %.3f us per particle-step: %.2f times the pace machine's\n", loop_us,
              loop_us / kPaceMachineUs);
  ServedScene served(dir, "default --state-dir states");
  ASSERT_GT(served.port(), 0) << served.log();
  int status = 0;
  const std::string out = served.run_python("MACHINE = " + std::to_string(machine) + "\n" + in_chromium(R"py(
LIMIT = 60 * MACHINE * float(os.environ.get("THAW_TEST_TIME_SCALE", "1"))
ICE = "(() => { const h = history.filter((r) => r[1] !== null); return h.length ? h[h.length - 1][1] : null; })()"
async def shot(call, name):
    data = await call("Page.captureScreenshot", format="png")
    with open(name, "wb") as f:
        f.write(base64.b64decode(data["data"]))
async def scenario(call, js, until):
    print("frames", bool(await until("framesSeen > 0 || fps > 0", 30)))
    print("dryer on", await until("dryers.length === 1 && dryers[0].on", 30))
    start = await until(ICE, 30)
    t0 = time.time()
    await shot(call, "melt-start.png")
    start_pixels = await js("Array.from(document.getElementById('view').getContext('2d').getImageData(0, 0, 640, 480).data.filter((_, i) => i % 16 == 0))")
    reached = await until(f"{ICE} !== null && {ICE} <= {start} - 0.10", LIMIT)
    seconds = time.time() - t0
    print(f"[ info ] ice {start:.3f} -> {await js(ICE):.3f} of the start in {seconds:.1f} s of wall time (limit {LIMIT:.0f} s)")
    print("melted 10 %", bool(reached) and seconds <= LIMIT)
    await shot(call, "melt-10.png")
    hud = await js("document.getElementById('hud').textContent")
    print("[ info ] " + hud.replace("\n", " | "))
    print("pace shown", "s simulated per s" in hud and "heat ×1000" in hud)
    end_pixels = await js("Array.from(document.getElementById('view').getContext('2d').getImageData(0, 0, 640, 480).data.filter((_, i) => i % 16 == 0))")
    changed = sum(1 for a, b in zip(start_pixels, end_pixels) if abs(a - b) > 12)
    print(f"[ info ] {changed} of {len(start_pixels)} sampled pixels changed")
    print("picture changed", changed > len(start_pixels) // 50)
)py"),
                                            240, &status);
  EXPECT_EQ(status, 0) << out;
  expect_lines(out, {"connected True", "frames True", "dryer on True", "melted 10 % True", "pace shown True",
                     "picture changed True", "screenshot True"});
  for (std::size_t at = out.find("[ info ]"); at != std::string::npos; at = out.find("[ info ]", at + 1))
    std::printf("%s\n", out.substr(at, out.find('\n', at) - at).c_str());
  std::printf("[ info ] screenshots: %s, %s\n", (dir.path() / "melt-start.png").c_str(),
              (dir.path() / "melt-10.png").c_str());
  // THAW_TEST_SCREENSHOTS=DIR keeps them (docs/images/browser-melt-*.png come from here).
  if (const char* keep = std::getenv("THAW_TEST_SCREENSHOTS"))
    for (const char* name : {"melt-start.png", "melt-10.png"})
      std::filesystem::copy_file(dir.path() / name,
                                 std::filesystem::path(keep) / ("browser-" + std::string(name)),
                                 std::filesystem::copy_options::overwrite_existing);
  EXPECT_TRUE(served.stop()) << served.log();
}

// The page is the server's state: its controls come from the welcome (the dryer's slider shows the
// server's temperature, the speed and heat selects the server's pace); a dryer slider moves the server's
// dryer; "Reset view" puts the scene's camera back (a second client's welcome says where the camera is);
// a scene change by the select rebuilds the header and the panels (icicles-lamp has a lamp and no
// dryer) and the lamp control switches the lamp; back in default the sliders show the new scene's
// values, not the old page's, and the tension select turns tension on (the server says so); after a reload
// the page shows the quality the server has.
TEST(BrowserClient, ThePageFollowsTheServerAcrossScenesAndReloads) {
  ASSERT_TRUE(std::filesystem::exists("/usr/bin/chromium"))
      << "Debian's chromium is not installed (scripts/setup)";
  TempDir dir("browser-state");
  ServedScene served(dir, "default --set spacing=0.006 --state-dir states");
  ASSERT_GT(served.port(), 0) << served.log();
  int status = 0;
  const std::string out = served.run_python(in_chromium(R"py(
import thaw_client
URL = f"ws://127.0.0.1:{PORT}/"
async def camera_now():
    async with thaw_client.connect(URL) as other:
        return other.welcome["camera"]["azimuth"]
def value(id):
    return f"document.getElementById('{id}').value"
async def scenario(call, js, until):
    print("welcome", await until("document.getElementById('scene-name').textContent === 'default' && dryers.length === 1", 30))
    print("sliders", await js(value('dryer-temp')), await js(value('speed')), await js(value('heat-scale')))
    await js("{ const s = document.getElementById('dryer-temp'); s.value = 120; s.dispatchEvent(new Event('input')); }")
    print("dryer set", bool(await until("dryers[0].temperature === 120", 20)))
    await js("send('camera.orbit', {d_azimuth: 40})")
    await asyncio.sleep(0.5)
    print("orbited", await camera_now())
    await js("document.getElementById('reset-view').click()")
    await asyncio.sleep(0.5)
    print("reset view", await camera_now())
    await js("{ const s = document.getElementById('scene'); s.value = 'icicles-lamp'; s.dispatchEvent(new Event('change')); }")
    print("scene changed", bool(await until("document.getElementById('scene-name').textContent === 'icicles-lamp'", 60)))
    print("panels", await js("[document.getElementById('dryers').hidden, document.getElementById('lamps').hidden, lamps.length].join(' ')"))
    on = await js("lamps[0].on")
    await js("document.getElementById('lamp-on').click()")
    print("lamp toggled", bool(await until(f"lamps[0].on === {json.dumps(not on)}", 20)))
    await js("{ const s = document.getElementById('scene'); s.value = 'default'; s.dispatchEvent(new Event('change')); }")
    print("back", bool(await until("document.getElementById('scene-name').textContent === 'default' && dryers.length === 1", 60)))
    print("fresh sliders", await js(value('dryer-temp')), await js("document.getElementById('dryers').hidden"))
    await js("{ const s = document.getElementById('tension'); s.value = 'akinci2013'; s.dispatchEvent(new Event('change')); }")
    print("tension set", bool(await until("tension === 'akinci2013'", 60)))
    await js("{ const v = document.getElementById('view-kind'); v.value = 'slice'; v.dispatchEvent(new Event('change')); }")
    await asyncio.sleep(1.5)
    await call("Page.captureScreenshot", format="png")  # the slice, its colour bar labelled in the frame
    await js("{ const v = document.getElementById('view-kind'); v.value = 'surface'; v.dispatchEvent(new Event('change')); }")
    HUD = "document.getElementById('hud').textContent"
    print("quality shown", bool(await until(f"{HUD}.includes('fast 480×360 stretched')", 20)))
    # A drag on the canvas: frames march at half scale while it lasts, and the page says so.
    box = await js("(() => { const r = document.getElementById('view').getBoundingClientRect(); return [r.x + r.width / 2, r.y + r.height / 2]; })()")
    x, y = box
    await call("Input.dispatchMouseEvent", type="mousePressed", x=x, y=y, button="left", clickCount=1)
    seen = False
    for i in range(40):
        x += 3
        await call("Input.dispatchMouseEvent", type="mouseMoved", x=x, y=y, button="left", buttons=1)
        await asyncio.sleep(0.1)
        seen = seen or "moving 320×240 stretched" in await js(HUD)
    await call("Input.dispatchMouseEvent", type="mouseReleased", x=x, y=y, button="left", clickCount=1)
    print("moving shown", seen)
    print("settled", bool(await until(f"{HUD}.includes('fast 480×360 stretched')", 20)))
    await js("{ const s = document.getElementById('scale'); s.value = '0.5'; s.dispatchEvent(new Event('change')); }")
    shown = await until(f"{HUD}.includes('fast 320×240 stretched')", 20)
    async with thaw_client.connect(URL) as other:  # after the frame: its welcome then has the new scale
        print("detail set", other.welcome["quality"]["scale"] if shown else None)
    await js("document.getElementById('full-quality').click()")
    await asyncio.sleep(0.5)
    await call("Page.reload")
    await asyncio.sleep(1)
    print("reloaded", bool(await until("welcome && document.getElementById('full-quality').checked && document.getElementById('scale').value === '0.5'", 30)))
)py"),
                                            240, &status);
  EXPECT_EQ(status, 0) << out;
  expect_lines(
      out, {"connected True", "welcome True", "sliders 70 0 1000", "dryer set True", "orbited 70.0",
            "reset view 30.0", "scene changed True", "panels true false 1", "lamp toggled True", "back True",
            "fresh sliders 70 False", "tension set True", "quality shown True", "moving shown True",
            "settled True", "detail set 0.5", "reloaded True", "screenshot True"});
  std::printf("[ info ] screenshot: %s\n", (dir.path() / "browser.png").c_str());
  EXPECT_TRUE(served.stop()) << served.log();
}

}  // namespace
}  // namespace thaw
