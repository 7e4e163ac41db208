// The planner's browser test (run by planner_browser_test.cpp, which starts the CAD service, the world
// model, the controller, scripted executors with the real skill library and the console): headless
// Debian chromium through playwright-core, as the console's browser test. The tree is built by clicks
// only; the target's four holes are picked by clicking the 3D view where each hole's entry point (from
// the CAD service's features) projects on the screen, through the page's test hook screenOf(). Any
// failed check ends the script with exit code 1.
import fs from 'node:fs';
import path from 'node:path';
import { ART, call, check, closeBrowser, launchBrowser, openPlanner, waitForSkills } from './harness.mjs';

const result = {};
await waitForSkills(['Localize', 'YankMonitor', 'Screw']);
const features = (await call('/api/cad/features?model=object:target')).json;
check(features?.holes?.length === 4, `the CAD service lists the target's 4 holes (${features?.holes?.length})`);
result.cad_holes = features.holes;
// A bad pick is refused with where and what.
let r = await call('/api/planner/screws', { method: 'POST', body: { model: 'object:target', holes: [7] } });
check(r.status === 400 && /no hole 7/.test(r.json?.error), `a pick of a hole that does not exist -> 400 ${JSON.stringify(r.json)}`);

const browser = await launchBrowser();
try {
  const page = await openPlanner(browser);
  check(await page.locator('#planner-add-kind option[value="skill:Screw"]').count() === 1, 'the Screw skill is offered from the live library');

  // --- the tree, by clicks ---
  const addNode = async (value) => { await page.selectOption('#planner-add-kind', value); await page.click('#planner-add'); };
  const select = async (pointer) => page.click(`button.pnode[data-pointer="${pointer}"]`);
  await addNode('control:Sequence');
  await addNode('control:Parallel');              // into the Sequence: /root/children/0
  await addNode('skill:Localize');                // into the Parallel
  await page.selectOption('#param-object', 'target');
  await select('/root/children/0');
  await addNode('monitor:YankMonitor');
  await page.fill('#param-max_yank_n_per_s', '2000');
  await select('/root');
  await addNode('skill:Screw');                   // /root/children/1
  await page.fill('#planner-assumptions', 'inserted(load,target)');
  await page.fill('#planner-task-id', 'planned-screws');
  await select('/root/children/0');
  await page.fill('[data-field="name"]', 'localize with yank monitor');
  // Move the Screw up and down again (the order matters for the preconditions).
  await select('/root/children/1');
  await page.click('#planner-up');
  check(await page.locator('button.pnode[data-pointer="/root/children/0"]').innerText().then((t) => t.includes('Screw')), 'Up moved the Screw first');
  await page.click('#planner-down');
  check(await page.locator('button.pnode[data-pointer="/root/children/1"]').innerText().then((t) => t.includes('Screw')), 'Down moved it back');

  // --- the tree's resources, from the skill descriptions: the camera by Localize, the operator by Screw ---
  const claims = await page.$$eval('#planner-resources tr[data-resource]', (rows) => rows.map((r) =>
    `${r.dataset.resource}:${[...r.querySelectorAll('button[data-pointer]')].map((b) => b.dataset.pointer).join(',')}`));
  check(JSON.stringify(claims) === JSON.stringify(['camera:/root/children/0/children/0', 'operator:/root/children/1']),
    `the resources view lists each device with the leaves that claim it: ${claims}`);
  await page.click('#planner-resources tr[data-resource="operator"] button');
  check(await page.locator('button.pnode.selected').getAttribute('data-pointer') === '/root/children/1',
    'clicking a claim selects its leaf');
  result.resources = claims;

  // --- a bad threshold, shown on its node and field by the controller's validator ---
  await select('/root/children/0');
  await page.fill('[data-field="success_threshold"]', '2');
  await page.waitForFunction(() => document.querySelector('button.pnode[data-pointer="/root/children/0"]')?.classList.contains('invalid')
    && document.querySelector('[data-field="success_threshold"]')?.getAttribute('aria-invalid') === 'true', null, { timeout: 20000 });
  const fieldError = await page.locator('[data-field="success_threshold"]').locator('xpath=ancestor::div[contains(@class,"field")]').locator('.field-error').innerText();
  check(/success_threshold/.test(fieldError), `the field shows the validator's message: ${fieldError}`);
  const invalidNodes = await page.$$eval('button.pnode.invalid', (bs) => bs.map((b) => b.dataset.pointer));
  // The Screw is flagged too (its holes are not bound yet); the root and the Parallel's children are not.
  check(invalidNodes.includes('/root/children/0') && !invalidNodes.some((p) => p === '/root' || p.startsWith('/root/children/0/')),
    `the Parallel is flagged, not the root nor its children (flagged: ${invalidNodes})`);
  result.threshold_error = { node: '/root/children/0', field: await page.locator('[aria-invalid="true"]').first().getAttribute('data-field'), message: fieldError };
  await page.screenshot({ path: path.join(ART, 'planner-threshold-error.png'), fullPage: true });
  await page.fill('[data-field="success_threshold"]', '1');
  await page.waitForFunction(() => !document.querySelector('button.pnode[data-pointer="/root/children/0"]')?.classList.contains('invalid'), null, { timeout: 20000 });
  console.log('ok: the fixed threshold is no longer flagged');

  // --- pick the target's four holes in the 3D view ---
  await page.evaluate(() => window.scrollTo(0, 0));
  const hover = await page.evaluate((h) => window.rigger.planner.screenOf('target', h.entry_m), features.holes[0]);
  await page.mouse.move(hover.x, hover.y);
  await page.waitForFunction(() => window.rigger.planner.view.hovered === 'target:hole:0', null, { timeout: 10000 });
  console.log('ok: hovering hole 0 highlights it');
  for (const h of features.holes) {
    const p = await page.evaluate((hole) => window.rigger.planner.screenOf('target', hole.entry_m), h);
    await page.mouse.click(p.x, p.y);
  }
  const picks = await page.evaluate(() => window.rigger.planner.state.picks.map((p) => ({ kind: p.kind, hole: p.hole, entity: p.entity, sig: p.ref.signature.type })));
  check(picks.length === 4 && picks.every((p, i) => p.kind === 'hole' && p.hole === features.holes[i].index && p.entity === 'target' && p.sig === 'cylinder'),
    `four holes picked in the 3D view, in order ${JSON.stringify(picks)}`);
  check(await page.locator('ol.picks li[data-kind="hole"]').count() === 4, 'the selection list shows the four picks with their references');
  await page.screenshot({ path: path.join(ART, 'planner-picks.png'), fullPage: true });

  // --- the Screw skill's holes from the picks ---
  await select('/root/children/1');
  await page.click('#planner-bind-holes');
  await page.waitForFunction(() => document.querySelectorAll('#planner-screws tr').length === 5, null, { timeout: 20000 });
  const params = await page.evaluate(() => window.rigger.planner.state.doc.root.children[1].params.holes);
  check(params.length === 4 && new Set(params).size === 4 && params.every((f) => /^target\/h[1-4]$/.test(f)),
    `the Screw's holes are the world model's four screw-hole features ${JSON.stringify(params)}`);
  await page.waitForSelector('#planner-valid', { timeout: 20000 });
  console.log('ok: the tree validates');

  // --- export (download), then the same text validated by the console, then reopened ---
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#planner-export')]);
  const exportedPath = path.join(ART, 'planned-screws.json');
  await download.saveAs(exportedPath);
  const exported = fs.readFileSync(exportedPath, 'utf8');
  result.exported = exported;
  r = await call('/api/planner/validate', { method: 'POST', body: exported });
  check(r.status === 200 && r.json.ok === true, `the exported recipe validates ${JSON.stringify(r.json?.errors)}`);
  const doc = JSON.parse(exported);
  const screws = doc.root.children[1].bindings.holes.screws;
  check(screws.every((s, i) => JSON.stringify(s.pose.position_m) === JSON.stringify(features.holes[i].entry_m)),
    'the exported screw positions are the CAD service\'s hole entries');
  // Opening a recipe re-checks its bindings with the CAD service; each open waits for its own check, so
  // that one still in flight is not taken for the next one's.
  const openChecked = async (file) => {
    const n = await page.evaluate(() => window.rigger.planner.state.bindingsChecked || 0);
    await page.setInputFiles('#planner-open', file);
    await page.waitForFunction((k) => window.rigger.planner.state.bindingsChecked > k && window.rigger.planner.state.validation, n, { timeout: 20000 });
  };
  await openChecked(exportedPath);
  await select('/root/children/1');
  await page.waitForFunction(() => document.querySelectorAll('#planner-screws tr').length === 5, null, { timeout: 20000 });
  console.log('ok: the reopened recipe has its screw binding back');
  // A binding whose reference no longer matches the model (as after an edit of the STEP file) is flagged
  // on its node when the recipe is opened, and the recipe is not valid; the good file clears it again.
  const tampered = JSON.parse(exported);
  tampered.root.children[1].bindings.holes.screws[2].ref.signature.radius_m += 0.001;
  const tamperedPath = path.join(ART, 'planned-screws-stale.json');
  fs.writeFileSync(tamperedPath, JSON.stringify(tampered));
  await openChecked(tamperedPath);
  const stale = await page.evaluate(() => window.rigger.planner.state.errors.filter((e) => /stale/.test(e.message)));
  check(stale.length === 1 && stale[0].pointer === '/root/children/1/bindings/holes' && /CAD_STALE_REFERENCE/.test(stale[0].message),
    `the changed reference is flagged as a stale binding on the Screw ${JSON.stringify(stale)}`);
  check(await page.locator('button.pnode.invalid[data-pointer="/root/children/1"]').count() === 1, 'the Screw node is flagged');
  await openChecked(exportedPath);
  await page.waitForSelector('#planner-valid', { timeout: 20000 });
  console.log('ok: the good file opens valid again');

  // --- publish: select, confirm ---
  await page.click('#planner-publish');
  await page.waitForSelector('dialog[open]');
  await page.click('#confirm-yes');
  await page.waitForFunction(() => document.body.innerText.includes('Published planned-screws'), null, { timeout: 60000 });
  console.log('ok: published from the planner');
  await page.screenshot({ path: path.join(ART, 'planner.png'), fullPage: true });

  // --- editing: copy/paste by keys, undo/redo, wrap in a decorator, an operator decision ---
  const docText = () => page.evaluate(() => JSON.stringify(window.rigger.planner.state.doc));
  const kids = () => page.evaluate(() => window.rigger.planner.state.doc.root.children.length);
  const before = await docText();
  await select('/root/children/1');
  await page.keyboard.press('Control+c');
  await select('/root');
  await page.keyboard.press('Control+v');
  check(await kids() === 3, 'Ctrl+C on the Screw, Ctrl+V on the root: a third child');
  const pasted = await page.evaluate(() => window.rigger.planner.state.doc.root.children[2]);
  check(pasted.skill === 'Screw' && JSON.stringify(pasted.params.holes) === JSON.stringify(params) && pasted.bindings?.holes?.screws?.length === 4,
    'the pasted Screw has the copied holes and binding');
  await page.keyboard.press('Control+z');
  check(await docText() === before, 'Ctrl+Z: the tree before the paste');
  await page.keyboard.press('Control+y');
  check(await kids() === 3, 'Ctrl+Y: the paste again');
  await select('/root/children/2');
  await page.selectOption('#planner-wrap-kind', 'Retry');
  await page.click('#planner-wrap');
  check(await page.locator('button.pnode[data-pointer="/root/children/2"]').innerText().then((t) => t.includes('Retry') && t.includes('max_attempts=2')),
    'Wrap: the pasted Screw is in a Retry (2 attempts)');
  check(await page.locator('button.pnode[data-pointer="/root/children/2/child"]').innerText().then((t) => t.includes('Screw')), 'the Screw is the Retry\'s child');
  await select('/root/children/2');
  await page.fill('[data-field="max_attempts"]', '1001');
  await page.waitForFunction(() => document.querySelector('[data-field="max_attempts"]')?.getAttribute('aria-invalid') === 'true', null, { timeout: 20000 });
  const retryError = await page.locator('[data-field="max_attempts"]').locator('xpath=ancestor::div[contains(@class,"field")]').locator('.field-error').innerText();
  check(/max_attempts|1000/.test(retryError), `1001 attempts flagged on the Retry's field by the controller's validator: ${retryError}`);
  result.retry_error = retryError;
  await page.fill('[data-field="max_attempts"]', '3');
  await page.waitForFunction(() => document.querySelector('[data-field="max_attempts"]')?.getAttribute('aria-invalid') === 'false', null, { timeout: 20000 });
  console.log('ok: 3 attempts accepted');
  await select('/root');
  await addNode('decision:OperatorDecision');
  await page.waitForFunction(() => document.querySelector('button.pnode[data-pointer="/root/children/3"]')?.classList.contains('invalid'), null, { timeout: 20000 });
  console.log('ok: an OperatorDecision without options is flagged');
  await page.fill('[data-field="prompt"]', 'Localize the target again?');
  await addNode('skill:Localize');
  check(await page.evaluate(() => window.rigger.planner.state.selected) === '/root/children/3/options/0/child', 'Add on the decision made its first option');
  await page.selectOption('#param-object', 'target');
  check(await page.locator('li[data-pointer="/root/children/3/options/0/child"]').innerText().then((t) => t.includes('“option 1” →')), 'the option\'s label is shown on its node');
  const post = await page.locator('[data-conditions="postconditions"]').innerText();
  check(post.includes('localized(target)'), `the Localize form shows its postcondition with the parameter bound: ${post}`);
  await page.waitForFunction(() => !document.querySelector('button.pnode[data-pointer="/root/children/3"]')?.classList.contains('invalid'), null, { timeout: 20000 });
  console.log('ok: the decision with one option validates');
  // --- a pose from a point and two perpendicular edges (the paper's rule), picked in the 3D view ---
  const near = (a, b, tol = 1e-9) => a.every((v, i) => Math.abs(v - b[i]) <= tol);
  const lines = features.edges.filter((e) => e.signature?.type === 'line');
  const zTop = Math.max(...features.vertices.map((v) => v.point_m[2]));
  const top = lines.filter((e) => Math.abs(e.start_m[2] - zTop) < 1e-9 && Math.abs(e.end_m[2] - zTop) < 1e-9);
  const dir = (e) => { const d = e.end_m.map((v, i) => v - e.start_m[i]); const n = Math.hypot(...d); return d.map((v) => v / n); };
  const mid = (e) => e.start_m.map((v, i) => (v + e.end_m[i]) / 2);
  // What a click there would pick, as the view sees it (the load hangs above the target and hides some
  // edges from this camera): a user picks a corner whose edges they can see, and so does the test.
  const pickedAt = (point) => page.evaluate((pt) => {
    const q = window.rigger.planner.screenOf('target', pt);
    const p = window.rigger.planner.view.pickAt(q.x, q.y);
    return p && { kind: p.kind, vertex: p.vertex, edge: p.edge };
  }, point);
  let corner = null, corners = 0;
  for (const v of features.vertices.filter((x) => Math.abs(x.point_m[2] - zTop) < 1e-9)) {
    const at = top.filter((e) => near(e.start_m, v.point_m) || near(e.end_m, v.point_m));
    if (at.length !== 2 || Math.abs(dir(at[0]).reduce((acc, x, i) => acc + x * dir(at[1])[i], 0)) >= 1e-9) continue;
    corners += 1;
    const seen = [await pickedAt(v.point_m), await pickedAt(mid(at[0])), await pickedAt(mid(at[1]))];
    if (seen[0]?.vertex === v.index && seen[1]?.edge === at[0].index && seen[2]?.edge === at[1].index) { corner = { v, edges: at }; break; }
  }
  check(corner !== null, `the target's top face has a corner with two perpendicular straight edges in view (${corners} corners)`);
  await select('/root');
  await addNode('skill:Place');
  const placePtr = await page.evaluate(() => window.rigger.planner.state.selected);
  await page.click('#planner-clear-picks');
  await page.evaluate(() => window.scrollTo(0, 0));
  const clickModel = async (point) => { const q = await page.evaluate((pt) => window.rigger.planner.screenOf('target', pt), point); await page.mouse.click(q.x, q.y); };
  await clickModel(corner.v.point_m);
  await clickModel(mid(corner.edges[0]));
  await clickModel(mid(corner.edges[1]));
  const framePicks = await page.evaluate(() => window.rigger.planner.state.picks.map((p) => ({ kind: p.kind, vertex: p.vertex, edge: p.edge })));
  check(JSON.stringify(framePicks) === JSON.stringify([{ kind: 'vertex', vertex: corner.v.index }, { kind: 'edge', edge: corner.edges[0].index }, { kind: 'edge', edge: corner.edges[1].index }]),
    `a vertex and two edges picked in the 3D view ${JSON.stringify(framePicks)}`);
  await select(placePtr);
  await page.click('#planner-frame-pose');
  await page.waitForSelector('[data-frame-binding="pose"]', { timeout: 20000 });
  // The binding's own validation starts after this (edits are validated 250 ms after the last one).
  const validatedBefore = await page.evaluate(() => window.rigger.planner.state.validations);
  const placed = await page.evaluate((ptr) => { let v = window.rigger.planner.state.doc; for (const k of ptr.split('/').slice(1)) v = v[k]; return v; }, placePtr);
  const [r0, p0, y0] = placed.params.pose.rpy_deg.map((a) => a * Math.PI / 180);
  const xAxis = [Math.cos(y0) * Math.cos(p0), Math.sin(y0) * Math.cos(p0), -Math.sin(p0)];
  check(placed.params.pose.frame === 'target' && near(placed.params.pose.position_m, corner.v.point_m, 1e-8) && near(xAxis, dir(corner.edges[0]), 1e-6)
    && placed.bindings.pose.rule === 'edges' && placed.bindings.pose.model_sha256 === features.model_sha256,
    `Place's pose is the frame at the corner, x along the first edge, in the target's frame ${JSON.stringify(placed.params.pose)} (r ${r0})`);
  await page.waitForFunction((n) => (window.rigger.planner.state.validated || 0) > n, validatedBefore, { timeout: 20000 });
  const poseErrors = await page.evaluate((ptr) => window.rigger.planner.state.errors.filter((e) => e.pointer.startsWith(`${ptr}/params/pose`)), placePtr);
  check(poseErrors.length === 0, `the controller's validator accepts the picked pose ${JSON.stringify(poseErrors)}`);
  result.frame_from_edges = { corner: corner.v.point_m, edges: corner.edges.map((e) => e.index), pose: placed.params.pose };
  await page.screenshot({ path: path.join(ART, 'planner-frame.png'), fullPage: true });
  // A frame binding whose edge no longer matches the model is flagged when the recipe is opened.
  const withFrame = await page.evaluate(() => window.rigger.planner.state.doc);
  let node = withFrame;
  for (const k of placePtr.split('/').slice(1)) node = node[k];
  node.bindings.pose.args.edges[0].signature.centroid_m[0] += 0.01;  // as if the part had been edited
  const staleFramePath = path.join(ART, 'planned-frame-stale.json');
  fs.writeFileSync(staleFramePath, JSON.stringify(withFrame));
  await openChecked(staleFramePath);
  const staleFrame = await page.evaluate(() => window.rigger.planner.state.errors.filter((e) => /stale binding/.test(e.message)));
  check(staleFrame.length === 1 && staleFrame[0].pointer === `${placePtr}/bindings/pose`, `the changed edge is flagged on Place's pose binding ${JSON.stringify(staleFrame)}`);
  const after = await docText();
  let undos = 0;
  while ((await docText()) !== before && undos < 30) { await page.click('#planner-undo'); undos += 1; }
  check(await docText() === before, `Undo (${undos} clicks) brings back the published tree`);
  let redos = 0;
  while (!(await page.locator('#planner-redo').isDisabled()) && redos < 30) { await page.click('#planner-redo'); redos += 1; }
  check(redos === undos && await docText() === after, `Redo (${redos} clicks) brings back every edit`);
  result.undo_steps = undos;
  await page.screenshot({ path: path.join(ART, 'planner-editing.png'), fullPage: true });
} finally {
  await closeBrowser(browser, result);
}
