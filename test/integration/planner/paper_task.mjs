// The paper's task built in the planner by clicks and CAD picks only, run by
// planner_paper_task_test.cpp (which starts the world model, the CAD service, the controller, scripted
// executors announcing the real skill library and the console): headless Debian chromium through
// playwright-core. From an empty tree: localize target and load (each in a Retry), attach with a yank
// monitor in a Parallel — AttachRobotToLoad's grasp picked on its axes in the 3D view, its approach from
// the feature list —, insert visually guided with force and timer monitors in a Fallback whose recovery
// backs off and asks the operator (retry / abort), the four screws from the target's four holes clicked
// in the 3D view, release. Typed: the non-geometric values (object ids, limits, attempts, stand-offs,
// units chosen from the unit lists) and the texts — node names, the operator's question, the task's
// description — which are taken from the shipped recipe (recipes/crane_insert.json, SHIPPED), as a
// person would copy them. No coordinate, pose or feature name is typed. The page must show the tree and
// "valid"; the exported text goes to RESULT for the C++ side to compare with the shipped recipe.
// Synchronisation is on the page's state (waitForFunction), never a sleep; a failed check exits 1.
import fs from 'node:fs';
import path from 'node:path';
import { ART, MODULES, call, check, closeBrowser, countActions, env, launchBrowser, openPlanner, until, waitForSkills } from './harness.mjs';

const shipped = JSON.parse(fs.readFileSync(env('SHIPPED'), 'utf8'));
const result = { timings_ms: {} };
const t0 = Date.now();

const nodeAt = (doc, pointer) => pointer.split('/').slice(1).reduce((v, k) => v?.[k], doc);
/// Every node of a tree as [pointer, node], depth first (children, a decorator's child, options' children).
function nodes(node, ptr = '/root') {
  const kids = node.children ? node.children.map((c, i) => [`${ptr}/children/${i}`, c])
    : node.child ? [[`${ptr}/child`, node.child]]
      : (node.options || []).map((o, i) => [`${ptr}/options/${i}/child`, o.child]);
  return [[ptr, node], ...kids.flatMap(([p, c]) => nodes(c, p))];
}

await waitForSkills(['Localize', 'AttachRobotToLoad', 'InsertVisuallyGuided', 'Screw', 'Release', 'YankMonitor', 'ForceMonitor', 'TimerMonitor']);
// The world model's features: where the test clicks (as a person would aim at what the page draws).
const world = {};
for (const e of ['load', 'target']) world[e] = (await call(`/api/world/entity/${e}`)).json?.features;
const holes = world.target?.screw_holes || [];
check(JSON.stringify(holes.map((h) => h.id)) === '["h1","h2","h3","h4"]', `the world model knows the target's screw holes h1..h4 (${holes.map((h) => h.id)})`);
result.world_features = world;

/// Rehearse clicked on the planned (exported and reopened) recipe: the run is followed in the page's
/// rehearsal view to its end; its end state and every node's shown state go to the result.
async function rehearse(page) {
  // The rehearsal cell's executors reach the console in their own time (READY on their domain first).
  const ids = (json) => (json.executors || []).map((e) => e.executor_id);
  await until('/api/rehearsal/state',
    (json) => ['robot-skills', 'perception-skills', 'operator-skills', 'monitors'].every((e) => ids(json).includes(e)),
    (json) => `the console hears the rehearsal cell's executors within 60 s (has ${ids(json)})`, 60000);
  await page.evaluate(() => new Promise((ok) => requestIdleCallback(ok, { timeout: 10000 })));
  const tRun = Date.now();
  await page.click('#planner-rehearse');
  await page.waitForFunction(() => !document.querySelector('#rehearsal').hidden
    || /Not rehearsed/.test(document.querySelector('#planner-notice')?.textContent || ''), null, { timeout: 30000 });
  check(await page.locator('#rehearsal').isVisible(), `the planned recipe's rehearsal was accepted (${await page.locator('#planner-notice').innerText()})`);
  // Polled twice a second: chromium's software rendering must not starve the cell's real-time loops.
  await page.waitForFunction(() => window.rigger.planner.rehearsal.ended(), null, { timeout: 5 * 60000, polling: 500 });
  await page.waitForFunction(() => {
    const v = window.rigger.planner.rehearsal;
    const nodes = v.store.nodes.get(v.taskId);
    return nodes && [...nodes.values()].every((n) => document.querySelector(`#rehearsal li[data-node="${n.node_id}"] > .row`)?.dataset.state === n.state);
  }, null, { timeout: 10000 });
  const state = await page.evaluate(() => window.rigger.planner.rehearsal.state());
  const shown = await page.$$eval('#rehearsal li[data-node]', (lis) => Object.fromEntries(lis.map((li) => [li.dataset.node, li.querySelector(':scope > .row').dataset.state])));
  result.rehearsal = { state, shown, run_s: (Date.now() - tRun) / 1000 };
  await page.screenshot({ path: path.join(ART, 'paper-task-rehearsed.png'), fullPage: true });
  check(state === 'SUCCEEDED', `the planned task rehearsed on the simulated cell ended ${state} after ${result.rehearsal.run_s} s`);
}

const browser = await launchBrowser();
try {
  const [page, acts] = countActions(await openPlanner(browser));
  check(await page.evaluate(() => window.rigger.planner.state.doc.root === null), 'the tree starts empty');
  result.timings_ms.page_ready = Date.now() - t0;
  const tBuild = Date.now();

  // --- helpers: every edit is a click, a choice from a list, or a typed non-geometric value ---
  const state = (fn, arg) => page.evaluate(fn, arg);
  const select = (ptr) => page.click(`button.pnode[data-pointer="${ptr}"]`);
  /// Adds from the palette and checks the new node landed where the shipped recipe has it.
  const add = async (value, expected) => {
    await page.selectOption('#planner-add-kind', value);
    // An executor that missed its liveliness lease on a loaded machine is out of the library until it is
    // back: the palette keeps the choice, not offered ("no executor now"), and a person waits for it.
    await page.waitForFunction(() => !document.querySelector('#planner-add-kind').selectedOptions[0]?.disabled, null, { timeout: 20000 });
    await page.click('#planner-add');
    const at = await state(() => window.rigger.planner.state.selected);
    check(at === expected, `Add ${value} put the node at ${at}`);
    const name = nodeAt(shipped, expected)?.name;
    if (name) await page.fill('[data-field="name"]', name);
    return at;
  };
  const fill = (selector, value) => page.fill(selector, String(value));
  await page.addScriptTag({ path: path.join(MODULES, 'axe-core/axe.min.js') });
  const axe = () => page.evaluate(async () => (await window.axe.run(document)).violations.map((x) => `${x.id}: ${x.help} (${x.nodes.length}: ${x.nodes.map((n) => n.target).join(' ')})`));
  /// A number in another unit than the parameter's own: the unit chosen from its list, then the number.
  const quantity = async (param, value, unit) => { await page.selectOption(`#unit-${param}`, unit); await fill(`#param-${param}`, value); };
  /// An object parameter by a click on the part in the 3D view ("Pick in 3D", then the centroid of the
  /// part's highest upward face, which the framed view looks down on).
  const clickObject = async (param, entity) => {
    await page.click(`[data-frame="${entity}"]`);
    await page.click(`[data-pick-object="${param}"]`);
    await page.locator('.pview canvas').scrollIntoViewIfNeeded();  // the form's button may have scrolled it away
    const { x, y } = await page.evaluate((e) => {
      const faces = window.rigger.planner.view.parts.get(e).features.faces
        .filter((f) => f.signature?.type === 'plane' && f.signature.direction[2] > 0.99);
      const top = faces.reduce((a, b) => (b.signature.centroid_m[2] > a.signature.centroid_m[2] ? b : a));
      return window.rigger.planner.screenOf(e, top.signature.centroid_m);
    }, entity);
    await page.mouse.click(x, y);
    await page.waitForFunction(([p, e]) => document.querySelector(`#param-${p}`)?.value === e, [param, entity], { timeout: 10000 });
  };
  const insertParams = async (tolerance_mm) => {
    await clickObject('object', 'load');
    await clickObject('target', 'target');
    await quantity('tolerance_m', tolerance_mm, 'mm');
  };
  const monitors = async (at) => {
    await add('monitor:ForceMonitor', `${at}/children/1`);
    await fill('#param-max_force_n', 150);
    await add('monitor:TimerMonitor', `${at}/children/2`);
    await quantity('duration_s', 2, 'min');
  };
  const view = (entity) => page.click(`[data-frame="${entity}"]`);

  // --- the recipe's own fields ---
  await fill('#planner-task-id', 'crane-insert');
  await fill('#planner-assumptions', 'hooked(crane,load)');
  await fill('#planner-description', shipped.description);
  await fill('#planner-stop-timeout', 5);

  // --- localize the target (retried) ---
  await add('control:Sequence', '/root');
  await add('decorator:Retry', '/root/children/0');
  await fill('[data-field="max_attempts"]', 3);
  const emptyRetry = await axe();  // the tree draws "(empty: …)" under a decorator without a child
  check(emptyRetry.length === 0, `axe-core: no violations with an empty decorator drawn ${JSON.stringify(emptyRetry)}`);
  await add('skill:Localize', '/root/children/0/child');
  await clickObject('object', 'target');

  // --- localize the load and attach with a yank monitor (retried once) ---
  await select('/root');
  await add('decorator:Retry', '/root/children/1');
  await fill('[data-field="max_attempts"]', 2);
  await add('control:Sequence', '/root/children/1/child');
  await add('skill:Localize', '/root/children/1/child/children/0');
  await page.selectOption('#param-object', 'load');  // from the list of the cell's parts
  const attachPar = await add('control:Parallel', '/root/children/1/child/children/1');
  const attach = await add('skill:AttachRobotToLoad', `${attachPar}/children/0`);
  await page.selectOption('#param-object', 'load');

  // The grasp: its axes picked in the 3D view. The picker shows the parts' named features.
  await page.click('#planner-pick-grasp');
  await page.waitForSelector('#planner-features-grasp button[data-feature="load/grasp_side"]');
  const offered = await page.$$eval('#planner-features-grasp button[data-feature]', (bs) => bs.map((b) => b.dataset.feature));
  check(['load/grasp_side', 'load/pre_grasp', 'target/h1', 'target/h2', 'target/h3', 'target/h4'].every((f) => offered.includes(f)),
    `the picker lists the parts' named features ${JSON.stringify(offered)}`);
  result.offered_features = offered;
  await view('load');
  await page.evaluate(() => window.scrollTo(0, 0));
  const grasp = await state(() => window.rigger.planner.features.screenOf('load/grasp_side'));
  await page.mouse.move(grasp.x, grasp.y);
  await page.waitForFunction(() => window.rigger.planner.features.hovered === 'load/grasp_side'
    && document.querySelector('#planner-features-grasp button.hovered')?.dataset.feature === 'load/grasp_side', null, { timeout: 10000 });
  check(await state(() => window.rigger.planner.features.markers.get('load/grasp_side').dot.scale.x > 1),
    'hovering grasp_side\'s axes in the 3D view highlights the marker and its entry in the list');
  // axe-core on the planner page with the picker open (its list, the form, the tree, the 3D view).
  const violations = await axe();
  check(violations.length === 0, `axe-core: no violations on the planner with the feature picker open ${JSON.stringify(violations)}`);
  await page.screenshot({ path: path.join(ART, 'paper-task-feature-picker.png'), fullPage: true });
  await page.mouse.click(grasp.x, grasp.y);
  await page.waitForFunction(() => document.querySelector('#param-grasp')?.value === 'load/grasp_side', null, { timeout: 10000 });
  check(await page.locator('#planner-features-grasp').count() === 0, 'the pick filled grasp with load/grasp_side and closed the picker');
  check(await page.locator('[data-feature-binding="grasp"]').innerText().then((t) => t.includes('load/grasp_side')), 'the form shows the grasp\'s binding');
  check(await state(() => [...window.rigger.planner.features.markers].filter(([, m]) => m.group.visible).map(([ref]) => ref).join() === 'load/grasp_side'),
    'with the list closed the 3D view shows the axes of the node\'s feature only');
  // The approach: from the accessible list; its entry focused (as by Tab) highlights its axes in the 3D
  // view. Focus, not the mouse: the form's layout moves when the grasp's validation error goes away.
  await page.click('#planner-pick-approach');
  await page.focus('#planner-features-approach button[data-feature="load/pre_grasp"]');
  await page.waitForFunction(() => window.rigger.planner.features.hovered === 'load/pre_grasp'
    && window.rigger.planner.features.markers.get('load/pre_grasp').dot.scale.x > 1, null, { timeout: 10000 });
  console.log('ok: focusing pre_grasp in the list highlights its axes');
  await page.click('#planner-features-approach button[data-feature="load/pre_grasp"]');
  await page.waitForFunction(() => document.querySelector('#param-approach')?.value === 'load/pre_grasp', null, { timeout: 10000 });
  console.log('ok: approach picked from the list: load/pre_grasp');

  await add('monitor:YankMonitor', `${attachPar}/children/1`);
  await fill('#param-max_yank_n_per_s', 2000);

  // --- insert with monitors, or back off and ask the operator ---
  await select('/root');
  const fallback = await add('control:Fallback', '/root/children/2');
  const insertPar = await add('control:Parallel', `${fallback}/children/0`);
  await add('skill:InsertVisuallyGuided', `${insertPar}/children/0`);
  await insertParams(5);
  await monitors(insertPar);
  await select(fallback);
  const recover = await add('control:Sequence', `${fallback}/children/1`);
  await add('skill:InsertVisuallyGuided', `${recover}/children/0`);
  await insertParams(20);
  await fill('#param-standoff_y_m', -0.25);
  await fill('#param-standoff_z_m', 0.15);
  const decision = await add('decision:OperatorDecision', `${recover}/children/1`);
  await fill('[data-field="prompt"]', nodeAt(shipped, decision).prompt);
  const again = await add('control:Parallel', `${decision}/options/0/child`);
  await add('skill:InsertVisuallyGuided', `${again}/children/0`);
  await insertParams(5);
  await monitors(again);
  await select(decision);
  await add('decorator:Inverter', `${decision}/options/1/child`);
  await add('decorator:ForceSuccess', `${decision}/options/1/child/child`);
  await add('skill:Release', `${decision}/options/1/child/child/child`);
  await select(decision);
  await fill('[data-field="options/0/label"]', 'retry');
  await fill('[data-field="options/1/label"]', 'abort');

  // --- the four screws from the target's four holes, clicked in the 3D view in the order h1..h4 ---
  await select('/root');
  const screw = await add('skill:Screw', '/root/children/3');
  await page.click('#planner-clear-picks');
  await view('target');
  await page.evaluate(() => window.scrollTo(0, 0));
  for (const h of holes) {
    const q = await state((p) => window.rigger.planner.screenOf('target', p), h.pose.position_m);
    await page.mouse.click(q.x, q.y);
  }
  const picks = await state(() => window.rigger.planner.state.picks.map((p) => `${p.entity}:${p.kind}`));
  check(JSON.stringify(picks) === JSON.stringify(Array(4).fill('target:hole')), `four holes of the target picked in the 3D view ${JSON.stringify(picks)}`);
  await page.click('#planner-bind-holes');
  await page.waitForFunction(() => document.querySelectorAll('#planner-screws tr').length === 5, null, { timeout: 20000 });
  check(JSON.stringify(await state((p) => { let v = window.rigger.planner.state.doc; for (const k of p.split('/').slice(1)) v = v[k]; return v.params.holes; }, screw))
    === '["target/h1","target/h2","target/h3","target/h4"]', 'the Screw\'s holes are the four picked holes, h1..h4');

  await select('/root');
  await add('skill:Release', '/root/children/4');
  result.timings_ms.build = Date.now() - tBuild;

  // --- what the page shows: every node of the shipped tree, drawn where it is, and "valid" ---
  const want = nodes(shipped.root);
  const drawn = await page.$$eval('button.pnode', (bs) => bs.map((b) => [b.dataset.pointer, b.innerText]));
  check(drawn.length === want.length && want.every(([ptr, n]) => {
    const text = drawn.find(([p]) => p === ptr)?.[1] || '';
    return text.startsWith(n.type) && text.includes(n.skill || n.monitor || '') && (!n.name || text.includes(n.name));
  }), `the tree shows the ${want.length} nodes of the paper's task where the shipped recipe has them`);
  // The page's own Validate (edits are validated 250 ms after the last one): the answer to this click.
  const asked = await state(() => window.rigger.planner.state.validations);
  await page.click('#planner-validate');
  await page.waitForFunction((n) => {
    const s = window.rigger.planner.state;
    return s.validated > n && s.validated === s.validations && s.validation?.ok === true && document.querySelector('#planner-valid') !== null;
  }, asked, { timeout: 20000 });
  check(await page.locator('#planner-errors li').count() === 0 && (await page.locator('#planner-valid').innerText()).includes('valid'),
    'the page says valid: the controller would accept the recipe, no error listed');
  const finalViolations = await axe();
  check(finalViolations.length === 0, `axe-core: no violations with the whole tree drawn ${JSON.stringify(finalViolations)}`);
  await page.screenshot({ path: path.join(ART, 'paper-task.png'), fullPage: true });
  // What programming the task cost, as the page counted it and shows it: every action of this script.
  const effort = await state(() => ({ counts: window.rigger.planner.effort.counts(), shown: document.querySelector('#planner-effort').textContent }));
  result.effort = effort.counts;
  console.log(`programming effort: ${effort.shown}`);
  check(JSON.stringify(effort.counts) === JSON.stringify(acts),
    `the page counted the session's actions as they were made: ${JSON.stringify(effort.counts)}, made ${JSON.stringify(acts)}`);
  check(effort.shown.includes(`${acts.clicks} clicks`) && effort.shown.includes(`${acts.fields_typed} fields typed`), `the page shows the count: ${effort.shown}`);

  // --- export (download); the console validates the same text ---
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#planner-export')]);
  const exportedPath = path.join(ART, 'crane-insert-planned.json');
  await download.saveAs(exportedPath);
  const exported = fs.readFileSync(exportedPath, 'utf8');
  result.exported = exported;
  const r = await call('/api/planner/validate', { method: 'POST', body: exported });
  check(r.status === 200 && r.json.ok === true, `the exported recipe validates ${JSON.stringify(r.json?.errors)}`);

  // --- reopened: the feature bindings are checked with the world model again ---
  const openChecked = async (file) => {
    const n = await state(() => window.rigger.planner.state.bindingsChecked || 0);
    await page.setInputFiles('#planner-open', file);
    await page.waitForFunction((k) => window.rigger.planner.state.bindingsChecked > k && window.rigger.planner.state.validation, n, { timeout: 20000 });
  };
  await openChecked(exportedPath);
  await page.waitForSelector('#planner-valid', { timeout: 20000 });
  console.log('ok: the exported file reopens valid, its feature and screw bindings matching the world model and the CAD model');
  const moved = JSON.parse(exported);
  nodeAt(moved, attach).bindings.grasp.pose.position_m[2] += 0.002;
  const movedPath = path.join(ART, 'crane-insert-moved-grasp.json');
  fs.writeFileSync(movedPath, JSON.stringify(moved));
  await openChecked(movedPath);
  const stale = await state(() => window.rigger.planner.state.errors.filter((e) => /stale binding/.test(e.message)));
  check(stale.length === 1 && stale[0].pointer === `${attach}/bindings/grasp` && /moved by 2\.00 mm/.test(stale[0].message),
    `a grasp binding 2 mm off the world model's grasp_side is flagged on its node ${JSON.stringify(stale)}`);
  await openChecked(exportedPath);
  await page.waitForSelector('#planner-valid', { timeout: 20000 });

  // --- rehearsed on the simulated cell (when the test gives the console a rehearsal domain) ---
  if (process.env.REHEARSAL_DOMAIN) await rehearse(page);
  result.timings_ms.total = Date.now() - t0;
} finally {
  await closeBrowser(browser, result);
}
