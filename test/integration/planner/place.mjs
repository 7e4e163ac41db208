// A part placed by picks, run by planner_browser_test.cpp (the world model and the CAD service on the
// simulated cell's file and STEP models, the console): headless Debian chromium through playwright-core.
// The person hides the target, orbits the view to look at the load from below (a drag, as with the
// mouse), clicks its bottom face, orbits back, shows the target, clicks the target's top face off its centre, turns it a quarter, marks its pose known and places
// it: the page says what would change, the confirmation applies it as a cell revision and the 3D view
// redraws the load there. Two faces of one part are refused on the page. No coordinate is typed.
// Synchronisation is on the page's state, never a sleep; a failed check exits 1. RESULT: the picks and
// the answers, for the C++ side to check the world model's new pose.
import { call, check, closeBrowser, viewGestures, launchBrowser, openPlanner } from './harness.mjs';

const result = {};
const browser = await launchBrowser();
try {
  const page = await openPlanner(browser);
  const state = (fn, arg) => page.evaluate(fn, arg);
  const { box, orbit, clickAt } = await viewGestures(page);
  /// The plane face of `entity` whose outward normal is `n`, from the CAD features the page holds.
  const faceFacing = (entity, n) => state(([e, d]) => window.rigger.planner.view.parts.get(e).features.faces
    .find((f) => f.signature?.type === 'plane' && f.signature.direction.every((v, i) => Math.abs(v - d[i]) < 1e-6)), [entity, n]);

  // --- two faces of one part: refused on the page, nothing sent ---
  await page.click('[data-frame="target"]');
  const top = await faceFacing('target', [0, 0, 1]);
  const side = await faceFacing('target', [0, 1, 0]);  // the side the framed view looks at
  check(top && side, 'the target has an upward and a +y plane face');
  await clickAt('target', [-0.1, 0.05, 0]);
  await clickAt('target', side.signature.centroid_m);
  check(await page.locator('#planner-place').isDisabled(), 'Place is disabled with two faces of one part picked');
  const sameHint = await page.locator('#planner-place-hint').innerText();
  check(/both faces are of target/.test(sameHint), `the page says why: ${sameHint}`);
  result.same_part_hint = sameHint;
  await page.click('#planner-clear-picks');

  // --- the load's bottom face, seen from below with the target (in the way) hidden ---
  await page.click('[data-part="target"]');
  check(!(await page.locator('[data-part="target"]').isChecked()), 'the target is hidden');
  await page.click('[data-frame="load"]');
  await orbit(-0.3 * box.height);
  const bottom = await faceFacing('load', [0, 0, -1]);
  check(bottom, 'the load has a downward plane face');
  const own = await clickAt('load', bottom.signature.centroid_m);
  check(own.kind === 'face' && own.entity === 'load' && own.face === bottom.index,
    `the click from below picked the load's bottom face ${bottom.index} (got ${own.entity} ${own.kind} ${own.face})`);
  await orbit(0.3 * box.height);
  await page.click('[data-part="target"]');

  // --- the target's top face, off its centre ---
  await page.click('[data-frame="target"]');
  const onto = await clickAt('target', [0.08, -0.05, 0]);
  check(onto.kind === 'face' && onto.entity === 'target' && onto.face === top.index,
    `picked the target's top face ${top.index} (got ${onto.entity} ${onto.kind} ${onto.face})`);
  const hint = await page.locator('#planner-place-hint').innerText();
  check(await page.locator('#planner-place').isEnabled() && /lays load \(face \d+\) on target \(face \d+\)/.test(hint), `the page says what Place does: ${hint}`);

  // --- a quarter turn, Place, the changes confirmed ---
  await page.selectOption('#planner-place-turn', '90');
  await page.click('#planner-place-known');  // its pose is known there: no Localize needed
  await page.click('#planner-place');
  await page.waitForFunction(() => document.querySelector('#confirm[open]') || document.querySelector('#planner-notice.error'), null, { timeout: 20000 });
  check(await page.locator('#confirm[open]').count() === 1, `the console asked to confirm (${await page.locator('#planner-notice').innerText()})`);
  const question = await page.locator('#confirm-text').innerText();
  check(/known there: .*moved load \d+ mm, 90\.0°/.test(question), `the confirmation says what changes: ${question}`);
  await page.click('#confirm-yes');
  await page.waitForFunction(() => /^Placed load on target: cell revision \d+/.test(document.querySelector('#planner-notice')?.textContent || ''), null, { timeout: 20000 });
  result.notice = await page.locator('#planner-notice').innerText();
  // The 3D view follows the revision: the load is drawn where the world model now has it.
  const entity = (await call('/api/world/entity/load')).json;
  const world = { pose: entity.world_pose || entity.pose };
  await page.waitForFunction((p) => {
    const g = window.rigger.planner.view.parts.get('load')?.group;
    return g && Math.hypot(g.position.x - p[0], g.position.y - p[1], g.position.z - p[2]) < 1e-6;
  }, world.pose.position_m, { timeout: 20000 });
  result.own = { face: own.face, point_m: own.point_m, normal: bottom.signature.direction };
  result.onto = { face: onto.face, point_m: onto.point_m, normal: top.signature.direction };
  result.turn_deg = 90;
  result.world_pose = world.pose;
} finally {
  await closeBrowser(browser, result);
}
