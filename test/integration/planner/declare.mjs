// Declaring features by picks in a real browser (docs/console.md, "Declare a feature"), run by
// planner_browser_test.cpp with the same services as e2e.mjs: on the demo target, a grasp frame from its
// top face and a straight edge of it, and screw holes "all like" one picked hole, each confirmed in the
// page's dialog; the world model serves them at once (the page's feature list shows them). One bad input
// first: screw holes named so that they take the names of the target's own (h1…), refused in the panel
// with nothing committed. Last, a new version of the target's model with its first hole moved 2 mm
// (TARGET_MOVED) replaces it: the dialog names the rules into that hole, and they are dropped. Any failed
// check ends the script with exit code 1.
import path from 'node:path';
import { ART, call, check, closeBrowser, env, launchBrowser, openPlanner, waitForDrawnRevision } from './harness.mjs';

const result = {};
const features = (await call('/api/cad/features?model=object:target')).json;
check(features?.holes?.length === 4, `the CAD service lists the target's 4 holes (${features?.holes?.length})`);
const revisionBefore = (await call('/api/cell/history')).json.cell_revision;
result.revision_before = revisionBefore;

const browser = await launchBrowser();
try {
  const page = await openPlanner(browser);
  await page.evaluate(() => window.scrollTo(0, 0));
  const screen = (point) => page.evaluate((pt) => window.rigger.planner.screenOf('target', pt), point);
  const pickedAt = async (point) => {
    const q = await screen(point);
    return page.evaluate(([x, y]) => { const p = window.rigger.planner.view.pickAt(x, y); return p && { entity: p.entity, kind: p.kind, face: p.face, edge: p.edge, hole: p.hole }; }, [q.x, q.y]);
  };
  const click = async (point) => { const q = await screen(point); await page.mouse.click(q.x, q.y); };
  await page.click('#planner-declare summary');

  // --- bad input: screw holes named "h" would be h1…h4, the target's own names: refused, nothing committed ---
  await click(features.holes[0].entry_m);
  await page.selectOption('#planner-declare-kind', 'screw_holes');
  await page.fill('#planner-declare-name', 'h');
  await page.check('#planner-declare-like');
  await page.fill('#planner-declare-screw-type', 'M12x40');
  await page.fill('#planner-declare-torque', '60');
  await page.click('#planner-declare-submit');
  await page.waitForFunction(() => /^Nothing declared/.test(document.querySelector('#planner-declare-status').textContent), null, { timeout: 20000 });
  result.taken = await page.locator('#planner-declare-status').innerText();
  check(/already has a feature "h1"/.test(result.taken) && /#\/name/.test(result.taken), `the taken name is refused, at /name: ${result.taken}`);
  check((await call('/api/cell/history')).json.cell_revision === revisionBefore, 'nothing was committed');
  console.log(`ok: ${result.taken}`);

  // --- screw holes "all like this one": the same picked hole, named m ---
  await page.fill('#planner-declare-name', 'm');
  await page.click('#planner-declare-submit');
  await page.waitForSelector('#confirm-yes', { state: 'visible', timeout: 20000 });
  await page.click('#confirm-yes');
  await page.waitForFunction(() => /^Declared/.test(document.querySelector('#planner-declare-status').textContent), null, { timeout: 30000 });
  result.holes = await page.locator('#planner-declare-status').innerText();
  check(/target\/m1, target\/m2, target\/m3, target\/m4/.test(result.holes), `four screw holes declared: ${result.holes}`);
  await waitForDrawnRevision(page, Number(/cell revision (\d+)/.exec(result.holes)[1]));
  console.log(`ok: ${result.holes}`);

  // --- a grasp frame: the top face and a straight edge of it whose middle is in view ---
  await page.click('#planner-clear-picks');
  const zTop = Math.max(...features.vertices.map((v) => v.point_m[2]));
  const mid = (e) => e.start_m.map((v, i) => (v + e.end_m[i]) / 2);
  const top = features.edges.filter((e) => e.signature?.type === 'line' && Math.abs(e.start_m[2] - zTop) < 1e-9 && Math.abs(e.end_m[2] - zTop) < 1e-9);
  let chosen = null;
  for (const e of top) {
    const m = mid(e);
    const inward = [m[0] * 0.9, m[1] * 0.9, zTop];  // a little towards the face's middle (the target's origin is its centre)
    const [onEdge, onFace] = [await pickedAt(m), await pickedAt(inward)];
    if (onEdge?.kind === 'edge' && onEdge.edge === e.index && onFace?.kind === 'face' && onFace.entity === 'target') { chosen = { edge: e, point: inward, face: onFace.face }; break; }
  }
  check(chosen !== null, `a top edge of the target and the face beside it are in view (${top.length} top edges)`);
  await click(chosen.point);
  await click(mid(chosen.edge));
  await page.selectOption('#planner-declare-kind', 'grasp_frame');
  await page.fill('#planner-declare-name', 'grasp_declared');
  await page.click('#planner-declare-submit');
  await page.waitForSelector('#confirm-yes', { state: 'visible', timeout: 20000 });
  await page.click('#confirm-yes');
  await page.waitForFunction(() => /^Declared target\/grasp_declared/.test(document.querySelector('#planner-declare-status').textContent), null, { timeout: 30000 });
  check(await page.locator('#planner-declare-undo').count() === 1, 'the undo (a rollback) is offered after the commit');

  // --- the world model serves them, and the page's feature list follows the new revision ---
  await page.waitForFunction(() => {
    const refs = window.rigger.planner.features.features.map((f) => f.ref);
    return ['target/grasp_declared', 'target/m1', 'target/m4'].every((r) => refs.includes(r));
  }, null, { timeout: 30000 });
  const world = (await call('/api/world/entity/target')).json;
  result.world_features = world.features;
  result.revision_after = (await call('/api/cell/history')).json.cell_revision;
  result.face = chosen.face;
  result.edge = chosen.edge.index;
  await page.screenshot({ path: path.join(ART, 'planner-declared.png'), fullPage: true });
  console.log('ok: the declared features are in the page\'s feature list');

  // --- a new version of the target's model (TARGET_MOVED: its first hole 2 mm further out): the dialog names
  //     the rules the new model no longer carries before anything changes; confirmed, they are dropped ---
  await page.setInputFiles('#planner-import', env('TARGET_MOVED'));
  await page.waitForFunction(() => document.querySelector('#planner-imported-summary') || document.querySelector('#planner-import-error'), null, { timeout: 60000 });
  check(await page.locator('#planner-imported-summary').count() === 1, `the new version is read: ${await page.locator('#planner-imported').innerText()}`);
  await page.selectOption('#planner-replace-object', 'target');
  await page.click('#planner-replace-model');
  await page.waitForFunction(() => document.querySelector('#confirm[open]') || document.querySelector('#planner-notice.error'), null, { timeout: 30000 });
  check(await page.locator('#confirm[open]').count() === 1, `the console asked to confirm the new model (${await page.locator('#planner-notice').innerText()})`);
  const question = await page.locator('#confirm-text').innerText();
  result.replace_question = question;
  for (const dropped of ['target/h1 (hole: face', 'target/m1 (hole: face'])
    check(question.includes(dropped), `the dialog names ${dropped.split(' ')[0]} as not in the new model: ${question}`);
  for (const kept of ['target/h2 (', 'target/m2 ('])
    check(!question.includes(kept), `the dialog keeps ${kept.split(' ')[0]}: ${question}`);
  await page.click('#confirm-yes');
  await page.waitForFunction(() => /^Replaced the model of target: cell revision \d+/.test(document.querySelector('#planner-notice')?.textContent || ''), null, { timeout: 30000 });
  result.replaced = await page.locator('#planner-notice').innerText();
  check(/Declare again: .*target\/m1/.test(result.replaced), `the page says what to declare again: ${result.replaced}`);
  result.world_after_replace = (await call('/api/world/entity/target')).json.features;
} finally {
  await closeBrowser(browser, result);
}
