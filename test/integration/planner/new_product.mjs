// A new product in the Planner, run by planner_new_product_test.cpp (the world model and the CAD service on
// the simulated cell, the task controller, scripted executors announcing the real skill library and the
// console): headless Debian chromium through playwright-core. Two STEP files the repository does not ship
// (BRACKET: an L bracket with two through holes; PLATE: a base plate with six holes of two diameters,
// written with OpenCascade by the C++ side before the cell started) become the paper's task through the
// page only: both imported and added to the cell (the bracket loose, the plate fixed), the plate placed on
// the target ("the table") by picks, the plate's two markers and six screw holes (two patterns "all like this
// one", two torques), the bracket's grasp and approach (on its web's outer face, the robot's side), two
// markers (on the web's inner face, the camera's side), insertion (pinned by a hole of each) and rope (a sling
// above its centre of mass, which hangs it from the crane's hook where the shipped load hung) declared by
// picks, each a confirmed cell revision; then the paper's tree shape built by clicks (Localize ×2, Attach ∥ Yank, Insert ∥ Force ∥
// Timer with the back-off fallback, Screw over the six holes, Release), validated and exported. The cell is
// then rolled back to where the session started (by the API) and the same session in a new page must give
// the same recipe and cell document, byte for byte; that page rehearses (the console starts its rehearsal
// cell, the simulated cell in physics, on the revision), goes back to the plan and, once the console's cell is
// the simulated cell too (the test brings it up after the rehearsal cell stopped: the console's executors are
// then exactly CELL_EXECUTORS), publishes. The objects take
// the names the page proposes (the files'), and so do the features' names, the hole patterns' prefixes, the
// marker ids and sizes and the stand-off. Typed: screw types, torques and monitor limits — never a coordinate
// (the page's own count says which fields were typed; a coordinate fails the script).
// Synchronisation is on the page's state, never a sleep; a failed check exits 1. RESULT: what the page and
// the world model said, the export, the session's count and timings.
import fs from 'node:fs';
import path from 'node:path';
import { ART, call, check, closeBrowser, countActions, env, launchBrowser, openPlanner, viewGestures, waitForDrawnRevision, waitForExecutors, waitForSkills } from './harness.mjs';

const t0 = Date.now();
const result = { timings_ms: {} };
await waitForSkills(['Localize', 'AttachRobotToLoad', 'InsertVisuallyGuided', 'Screw', 'Release', 'YankMonitor', 'ForceMonitor', 'TimerMonitor']);
result.revision_before = (await call('/api/cell')).json.cell_revision;

/// The programming session on `page` (its actions counted in `acts`), from the two files to the exported
/// recipe; what the page and the world model said goes to `result`. Pictures in round 1 only.
async function session(page, acts, result, round) {
  shown = page;
  const tSession = Date.now();
  const state = (fn, arg) => page.evaluate(fn, arg);
  const picture = async (name, selector) => { if (round === 1) await page.locator(selector).first().screenshot({ path: path.join(ART, `new-product-${name}.png`) }); };
  const notice = () => page.locator('#planner-notice').innerText();
  const revisionIn = (text) => Number(/cell revision (\d+)/.exec(text)[1]);
  const gestures = await viewGestures(page);
  const { box, orbit } = gestures;
  /// A click on `entity`'s model point `p` where the page draws it, the view scrolled into sight first
  /// (a panel opened above it or a screenshot may have moved it).
  const clickAt = async (entity, p) => {
    await page.locator('.pview canvas').scrollIntoViewIfNeeded();
    return gestures.clickAt(entity, p);
  };
  const features = (entity) => state((e) => window.rigger.planner.view.parts.get(e).features, entity);
  /// The plane face of `entity` whose outward normal is `n` and whose centroid has `axis` at `at` (m).
  const planeFace = async (entity, n, test = () => true) => (await features(entity)).faces
    .filter((f) => f.signature?.type === 'plane' && f.signature.direction.every((v, i) => Math.abs(v - n[i]) < 1e-6))
    .find((f) => test(f.signature.centroid_m));
  /// Whether a click at model point `p` of `entity` picks face `face` where the view draws it now (on the canvas).
  const picksFace = (entity, face, p) => state(([e, f, pt]) => {
    const q = window.rigger.planner.screenOf(e, pt);
    const r = window.rigger.planner.view.renderer.domElement.getBoundingClientRect();
    if (q.x < r.left + 2 || q.x > r.right - 2 || q.y < r.top + 2 || q.y > r.bottom - 2) return false;
    const hit = window.rigger.planner.view.pickAt(q.x, q.y);
    return Boolean(hit && hit.entity === e && hit.kind === 'face' && hit.face === f);
  }, [entity, face, p]);
  /// The first of `points` where a square of half-size `half` (m, in the face's plane: x and y, or y and
  /// z for an x-facing face) lies whole on `face` in view: its centre and four corners pick it.
  const spotOn = async (entity, face, points, half = 0, plane = [0, 1]) => {
    for (const p of points) {
      let fits = true;
      for (const [i, j] of [[0, 0], [-1, -1], [1, -1], [1, 1], [-1, 1]]) {
        const q = [...p];
        q[plane[0]] += half * i;
        q[plane[1]] += half * j;
        if (!(await picksFace(entity, face, q))) { fits = false; break; }
      }
      if (fits) return p;
    }
    return null;
  };
  /// What `find` gives, the view turned round a little at a time until it gives something, as a person does.
  const turnUntil = async (find) => {
    let found = await find();
    for (let turns = 0; turns < 12 && !found; ++turns) {
      await orbit(0, 0.08 * box.height);
      found = await find();
    }
    return found;
  };
  /// Clicks the hole of `entity` whose entry is nearest (x, y) in its frame, from the side its axis points.
  const clickHole = async (entity, x, y) => {
    const hole = (await features(entity)).holes.filter((h) => h.axis[2] > 0.99)
      .reduce((a, b) => (Math.hypot(b.entry_m[0] - x, b.entry_m[1] - y) < Math.hypot(a.entry_m[0] - x, a.entry_m[1] - y) ? b : a));
    const pick = await clickAt(entity, hole.entry_m);
    check(pick.entity === entity && pick.kind === 'hole', `picked a hole of ${entity} at [${x}, ${y}] (got ${pick.entity} ${pick.kind})`);
    return hole;
  };
  const confirmed = async (selector, re) => {
    await page.waitForSelector('#confirm-yes', { state: 'visible', timeout: 30000 });
    await page.click('#confirm-yes');
    await page.waitForFunction(([s, r]) => new RegExp(r).test(document.querySelector(s)?.textContent || ''), [selector, re], { timeout: 30000 });
    const text = await page.locator(selector).innerText();
    await waitForDrawnRevision(page, revisionIn(text));
    return text;
  };
  const declare = async (kind, fields = {}, ticked = []) => {
    await page.selectOption('#planner-declare-kind', kind);
    // A box stays ticked after a declaration: ticked once.
    for (const id of ticked) if (!(await page.isChecked(`#planner-declare-${id}`))) await page.click(`#planner-declare-${id}`);
    for (const [id, value] of Object.entries(fields)) await page.fill(`#planner-declare-${id}`, String(value));
    const before = await page.locator('#planner-declare-status').innerText();
    await page.click('#planner-declare-submit');
    await page.waitForFunction((b) => document.querySelector('#confirm[open]')
      || document.querySelector('#planner-declare-status').textContent !== b, before, { timeout: 20000 });
    check(await page.locator('#confirm[open]').count() === 1, `the console asked to confirm the ${kind} (${await page.locator('#planner-declare-status').innerText()})`);
    result[`${kind}_dialog`] = await page.locator('#confirm').innerText();
    const text = await confirmed('#planner-declare-status', '^Declared ');
    await page.click('#planner-clear-picks');
    return text;
  };

  // --- import both files; each becomes a cell object by its name ---
  const add = async (file, id, material) => {
    await page.setInputFiles('#planner-import', file);
    await page.waitForFunction(() => document.querySelector('#planner-imported-summary') || document.querySelector('#planner-import-error'), null, { timeout: 60000 });
    const summary = await page.locator('#planner-imported-summary, #planner-import-error').first().innerText();
    // The name the page proposes, the file's: nothing typed.
    await page.waitForFunction((n) => document.querySelector('#planner-add-name')?.value === n, id, { timeout: 10000 });
    await page.selectOption('#planner-add-material', material);
    await page.click('#planner-add-object');
    const added = await confirmed('#planner-notice', `^Added ${id} to the cell: cell revision \\d+`);
    await page.waitForFunction((e) => window.rigger.planner.view.parts.get(e)?.features?.faces?.length > 0, id, { timeout: 60000 });
    return { summary, added };
  };
  result.bracket_import = await add(env('BRACKET'), 'bracket', 'steel');  // the crane's load: loose
  check(/^bracket\.step: units m, 2 solids, \d+ faces, 2 holes/.test(result.bracket_import.summary), `the bracket's file: ${result.bracket_import.summary}`);
  result.plate_import = await add(env('PLATE'), 'base_plate', 'fixed');  // what the bracket goes into: fixed
  check(/^base_plate\.step: units m, 2 solids, \d+ faces, 6 holes/.test(result.plate_import.summary), `the plate's file: ${result.plate_import.summary}`);
  await picture('1-imported', '.pview');
  result.timings_ms.imported = Date.now() - tSession;

  // --- the plate placed on the target's top face: its bottom face seen from below, then the target ---
  // (its tab's bottom looks down too, on the plate's top)
  const plateBottom = await planeFace('base_plate', [0, 0, -1], (c) => c[2] < -0.02);
  await page.click('[data-frame="base_plate"]');
  await orbit(-0.3 * box.height);
  const own = await clickAt('base_plate', [0.0, -0.08, plateBottom.signature.centroid_m[2]]);
  check(own.kind === 'face' && own.face === plateBottom.index, `picked the plate's bottom face ${plateBottom.index} (got ${own.kind} ${own.face})`);
  await orbit(0.3 * box.height);
  await page.click('[data-frame="target"]');
  const onto = await clickAt('target', [0.03, 0.0, 0]);
  check(onto.entity === 'target' && onto.kind === 'face', `picked the target's top face (got ${onto.entity} ${onto.kind})`);
  await page.click('#planner-place-known');
  await page.click('#planner-place');
  result.placed = await confirmed('#planner-notice', '^Placed base_plate on target: cell revision \\d+');
  await page.click('[data-frame="base_plate"]');
  await picture('2-placed', '.pview');

  // --- the plate's six screw holes: the four 17.5 mm "all like this one", then the two 14 mm ---
  await page.click('#planner-declare summary');
  await clickHole('base_plate', -0.15, -0.12);
  result.holes_a = await declare('screw_holes', { 'screw-type': 'M20x60', torque: 120 }, ['like']);  // the prefix proposed: a
  check(/base_plate\/a1, base_plate\/a2, base_plate\/a3, base_plate\/a4:/.test(result.holes_a), `four holes like the first: ${result.holes_a}`);
  await clickHole('base_plate', -0.05, 0.0);
  result.holes_b = await declare('screw_holes', { 'screw-type': 'M16x50', torque: 80 });  // the prefix proposed next: b
  check(/base_plate\/b1, base_plate\/b2:/.test(result.holes_b), `two holes like the second: ${result.holes_b}`);
  await picture('3-holes', '#planner-declare');
  // --- the plate's two markers on its tab's outer face, which faces the camera (80 mm and the ids proposed) ---
  const tab = await planeFace('base_plate', [1, 0, 0], (c) => Math.abs(c[0] - 0.3) < 1e-6 && c[2] > 0.01);
  check(tab, 'the plate has its tab\'s outer (+x) face');
  await page.click('[data-frame="base_plate"]');
  await orbit(-0.12 * box.height);  // tilted down to see it more from the side
  const tabSpots = async () => {
    const spots = [];
    for (const y of [-0.06, 0.06]) spots.push(await spotOn('base_plate', tab.index, [[0.3, y, 0.06]], 0.045, [1, 2]));
    return spots.every(Boolean) ? spots : null;
  };
  const spots = await turnUntil(tabSpots);
  check(spots, 'the plate\'s tab has room for two 80 mm markers in view');
  result.plate_markers = [];
  for (const spot of spots) {
    await clickAt('base_plate', spot);
    result.plate_markers.push(await declare('marker'));  // the id proposed: the lowest no object carries
  }
  // Where the insertion's face is picked: the plate's top, clear of its holes.
  await page.click('[data-frame="base_plate"]');
  const plateTop = await planeFace('base_plate', [0, 0, 1], (c) => Math.abs(c[2]) < 1e-6);
  const plateSpot = await spotOn('base_plate', plateTop.index, [[-0.08, -0.08, 0], [0.03, -0.08, 0], [0.0, 0.06, 0]]);
  check(plateSpot, 'the plate\'s top face is in view');

  // --- the bracket: grasp and approach on its web's outer face (the robot's side, hanging as it stands),
  //     tool x down along its vertical edge: the view turned half round to see it ---
  await page.click('[data-frame="bracket"]');
  // (the base plate's end face looks the same way: the web's is the one above it)
  const webFace = await planeFace('bracket', [-1, 0, 0], (c) => Math.abs(c[0] + 0.2) < 1e-6 && c[2] > 0.1);
  check(webFace, 'the bracket has its web\'s outer (-x) face');
  // Tilted down to look at it more from the side, then turned round until it is in view.
  await orbit(-0.12 * box.height);
  const webSpot = await turnUntil(() => spotOn('bracket', webFace.index, [[-0.2, 0.0, 0.2], [-0.2, 0.05, 0.25], [-0.2, -0.05, 0.15]], 0.02, [1, 2]));
  check(webSpot, 'the web\'s outer face is in view');
  const webEdges = (await features('bracket')).edges.filter((e) => e.signature?.type === 'line'
    && [e.start_m, e.end_m].every((p) => Math.abs(p[0] + 0.2) < 1e-6) && Math.abs(e.start_m[2] - e.end_m[2]) > 0.2);
  // A point of the edge, on the canvas, that picks it (`mid`: where it is clicked).
  let webEdge = null;
  for (const e of webEdges) {
    for (const f of [0.5, 0.35, 0.65, 0.2, 0.8]) {
      const mid = e.start_m.map((v, i) => v + f * (e.end_m[i] - v));
      const hit = await state(([pt]) => {
        const q = window.rigger.planner.screenOf('bracket', pt);
        const r = window.rigger.planner.view.renderer.domElement.getBoundingClientRect();
        if (q.x < r.left + 2 || q.x > r.right - 2 || q.y < r.top + 2 || q.y > r.bottom - 2) return null;
        const h = window.rigger.planner.view.pickAt(q.x, q.y);
        return h && { kind: h.kind, edge: h.edge };
      }, [mid]);
      if (hit?.kind === 'edge' && hit.edge === e.index) { webEdge = { ...e, mid }; break; }
    }
    if (webEdge) break;
  }
  check(webEdge, `a vertical edge of the web's outer face is in view (${webEdges.length} such edges)`);
  // x along the edge from its first vertex to its last: reversed when that is up.
  const down = webEdge.end_m[2] > webEdge.start_m[2] ? ['xrev'] : [];
  // The edge first: a picked face is drawn a little proud of itself, over its edges where it is seen at a slant.
  const frameByPicks = async (kind, fields = {}) => {
    const edge = await clickAt('bracket', webEdge.mid);
    check(edge.kind === 'edge' && edge.edge === webEdge.index, `picked the web's edge ${webEdge.index} (got ${edge.kind} ${edge.edge})`);
    const face = await clickAt('bracket', webSpot);
    check(face.kind === 'face' && face.face === webFace.index, `picked the web's outer face ${webFace.index} (got ${face.kind} ${face.face})`);
    return declare(kind, fields, down);
  };
  result.grasp = await frameByPicks('grasp_frame');  // the name proposed: grasp
  result.approach = await frameByPicks('approach_waypoint');  // the name and stand-off proposed: pre_grasp, 100 mm
  // --- its two markers on the web's inner face, which faces the camera ---
  await page.click('[data-frame="bracket"]');
  const innerFace = await planeFace('bracket', [1, 0, 0], (c) => Math.abs(c[0] + 0.17) < 1e-6);
  check(innerFace, 'the bracket has its web\'s inner (+x) face');
  result.bracket_markers = [];
  for (const y of [-0.075, 0.075]) {
    const spot = await spotOn('bracket', innerFace.index, [[-0.17, y, 0.18], [-0.17, y, 0.2]], 0.045, [1, 2]);
    check(spot, `the web's inner face has room for an 80 mm marker at y ${y} in view`);
    await clickAt('bracket', spot);
    result.bracket_markers.push(await declare('marker'));
  }
  // --- the insertion: the bracket's bottom face (from below) on the plate's top face ---
  const bracketBottom = await planeFace('bracket', [0, 0, -1]);
  // Dragged down a little at a time until the bottom face is under the pointer, as a person does.
  await page.click('[data-frame="bracket"]');
  let dragged = 0;
  for (; dragged < 10 && !(await picksFace('bracket', bracketBottom.index, [-0.05, 0.0, 0.0])); ++dragged) await orbit(-0.06 * box.height);
  const mating = await clickAt('bracket', [-0.05, 0.0, 0.0]);
  check(mating.kind === 'face' && mating.face === bracketBottom.index, `picked the bracket's bottom face ${bracketBottom.index} after ${dragged} drags (got ${mating.kind} ${mating.face})`);
  await page.click('[data-frame="base_plate"]');
  const into = await clickAt('base_plate', plateSpot);
  check(into.entity === 'base_plate' && into.face === plateTop.index, `picked the plate's top face (got ${into.entity} ${into.kind} ${into.face})`);
  // Pinned: the bracket's hole at (0.06, -0.09) on the plate's 14 mm hole at (0.09, 0.04), which leaves the
  // plate's markers free.
  await page.click('[data-frame="bracket"]');
  await clickHole('bracket', 0.06, -0.09);
  await page.click('[data-frame="base_plate"]');
  await clickHole('base_plate', 0.09, 0.04);
  result.insertion = await declare('insertion');
  // --- its rope: a sling above its centre of mass (any pick names the part); the bracket then hangs where
  //     the crane's load hung, and the load stands where the bracket stood ---
  await page.click('[data-frame="bracket"]');
  await clickHole('bracket', 0.06, 0.09);
  result.rope = await declare('rope_attachment', {}, ['sling']);
  check(/The crane's rope moves from load to bracket: it becomes the crane's load, hanging where load hung, and load is set down where bracket stood/
    .test(result.rope_attachment_dialog), `the dialog said where the rope goes: ${result.rope_attachment_dialog}`);
  result.revision_declared = (await call('/api/cell')).json.cell_revision;
  result.timings_ms.declared = Date.now() - tSession;
  result.world = {};
  for (const e of ['bracket', 'base_plate', 'target', 'load']) result.world[e] = (await call(`/api/world/entity/${e}`)).json;

  // --- the paper's tree shape by clicks, choices from lists and the monitors' limits ---
  const nodeSel = (ptr) => page.click(`button.pnode[data-pointer="${ptr}"]`);
  const node = async (value, expected) => {
    await page.selectOption('#planner-add-kind', value);
    // An executor that missed its liveliness lease on a loaded machine is out of the library until it is
    // back: the palette keeps the choice, not offered ("no executor now"), and a person waits for it.
    await page.waitForFunction(() => !document.querySelector('#planner-add-kind').selectedOptions[0]?.disabled, null, { timeout: 20000 });
    await page.click('#planner-add');
    const at = await state(() => window.rigger.planner.state.selected);
    check(at === expected, `Add ${value} put the node at ${at}, expected ${expected}`);
    // What was added: the palette is rebuilt when an executor's announcement comes or goes.
    const added = await state((ptr) => { let v = window.rigger.planner.state.doc; for (const k of ptr.split('/').slice(1)) v = v[k]; return v; }, at);
    const [kind, name] = value.split(':');
    check(kind === 'control' ? added.type === name : (added.skill || added.monitor) === name,
      `Add ${value} added ${JSON.stringify(added).slice(0, 120)} (the palette offered ${await page.inputValue('#planner-add-kind')})`);
    return at;
  };
  const object = (param, id) => page.selectOption(`#param-${param}`, id);
  const monitored = async (at) => {
    await node('monitor:ForceMonitor', `${at}/children/1`);
    await page.fill('#param-max_force_n', '150');
    await node('monitor:TimerMonitor', `${at}/children/2`);
    await page.fill('#param-duration_s', '120');
  };
  const insert = async (at) => {
    await node('skill:InsertVisuallyGuided', at);
    await object('object', 'bracket');
    await object('target', 'base_plate');
  };
  await node('control:Sequence', '/root');
  await node('skill:Localize', '/root/children/0');
  await object('object', 'base_plate');
  await node('skill:Localize', '/root/children/1');
  await object('object', 'bracket');
  await nodeSel('/root');
  const attachPar = await node('control:Parallel', '/root/children/2');
  await node('skill:AttachRobotToLoad', `${attachPar}/children/0`);
  await object('object', 'bracket');
  for (const [param, feature] of [['grasp', 'bracket/grasp'], ['approach', 'bracket/pre_grasp']]) {
    await page.click(`#planner-pick-${param}`);
    await page.click(`#planner-features-${param} button[data-feature="${feature}"]`);
    await page.waitForFunction(([p, f]) => document.querySelector(`#param-${p}`)?.value === f, [param, feature], { timeout: 10000 });
  }
  await node('monitor:YankMonitor', `${attachPar}/children/1`);
  await page.fill('#param-max_yank_n_per_s', '2000');
  await nodeSel('/root');
  const fallback = await node('control:Fallback', '/root/children/3');
  const insertPar = await node('control:Parallel', `${fallback}/children/0`);
  await insert(`${insertPar}/children/0`);
  await monitored(insertPar);
  await nodeSel(fallback);
  const recover = await node('control:Sequence', `${fallback}/children/1`);
  await insert(`${recover}/children/0`);  // the back-off: to the insertion's stand-off, at a coarse tolerance
  await page.selectOption('#unit-tolerance_m', 'mm');
  await page.fill('#param-tolerance_m', '20');
  await nodeSel(recover);
  const again = await node('control:Parallel', `${recover}/children/1`);
  await insert(`${again}/children/0`);
  await monitored(again);
  await nodeSel('/root');
  const screw = await node('skill:Screw', '/root/children/4');
  await object('object', 'bracket');
  await object('target', 'base_plate');
  await page.click('#planner-clear-picks');
  await page.click('[data-frame="base_plate"]');
  await page.evaluate(() => window.scrollTo(0, 0));
  const holes = result.world.base_plate.features.screw_holes;
  check(holes.length === 6, `the world model serves the plate's six holes (${holes.map((h) => h.id)})`);
  for (const h of holes) await clickAt('base_plate', h.pose.position_m);
  await page.click('#planner-bind-holes');
  await page.waitForFunction(() => document.querySelectorAll('#planner-screws tr').length === 7, null, { timeout: 20000 });
  result.screws_table = await page.$$eval('#planner-screws tr', (rows) => rows.map((r) => r.innerText));
  await nodeSel('/root');
  await node('skill:Release', '/root/children/5');
  await object('object', 'bracket');
  result.timings_ms.built = Date.now() - tSession;

  // --- valid, counted, exported ---
  const asked = await state(() => window.rigger.planner.state.validations);
  await page.click('#planner-validate');
  await page.waitForFunction((n) => {
    const s = window.rigger.planner.state;
    return s.validated > n && s.validated === s.validations && s.validation && document.querySelector('#planner-errors, #planner-valid');
  }, asked, { timeout: 20000 });
  const errors = await page.$$eval('#planner-errors li', (lis) => lis.map((li) => li.innerText));
  check(errors.length === 0 && await page.locator('#planner-valid').count() === 1, `the page says valid: ${JSON.stringify(errors)}`);
  await picture('4-tree', 'section[aria-labelledby="pt"]');
  const effort = await state(() => ({ counts: window.rigger.planner.effort.counts(), typed: window.rigger.planner.effort.typed(), shown: document.querySelector('#planner-effort').textContent }));
  result.effort = effort;
  result.actions = acts;
  result.timings_ms.session = Date.now() - tSession;
  console.log(`programming effort: ${effort.shown}; ${result.timings_ms.session / 1000} s`);
  check(JSON.stringify(effort.counts) === JSON.stringify(acts), `the page counted the session's actions as made: ${JSON.stringify(effort.counts)}, made ${JSON.stringify(acts)}`);
  const coordinates = effort.typed.filter((f) => f.coordinate).map((f) => f.name);
  check(coordinates.length === 0, `no coordinate typed (typed: ${effort.typed.map((f) => f.name).join(', ')})`);
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#planner-export')]);
  const exportedPath = path.join(ART, `new-product-${round}.json`);
  await download.saveAs(exportedPath);
  result.exported = fs.readFileSync(exportedPath, 'utf8');
  result.screw = screw;
  result.cell = (await call('/api/cell')).json;  // the revision the session made
}


let shown = null;  // the page the session runs on: its picture and state go to the log folder on a failure
const browser = await launchBrowser();
try {
  const [page, acts] = countActions(await openPlanner(browser));
  result.timings_ms.page_ready = Date.now() - t0;
  await session(page, acts, result, 1);
  await page.close();

  // --- canonical: the cell rolled back to where the session started, the same session again in a new page
  //     gives the same recipe and the same cell document, byte for byte ---
  const tReplay = Date.now();
  const rollback = await call('/api/cell/revisions', { method: 'POST', body: { rollback: result.revision_before, comment: 'the new product again' } });
  check(rollback.json?.confirmation_id, `the rollback was offered ${JSON.stringify(rollback.json)}`);
  const rolled = await call('/api/confirm', { method: 'POST', body: { confirmation_id: rollback.json.confirmation_id } });
  check(rolled.status < 300, `the rollback was applied ${JSON.stringify(rolled.json)}`);
  const [again, actsAgain] = countActions(await openPlanner(browser));
  result.replay = { timings_ms: {} };
  await session(again, actsAgain, result.replay, 2);
  result.timings_ms.replay = Date.now() - tReplay;
  check(result.replay.exported === result.exported, 'the same session exports the same recipe, byte for byte');
  check(result.replay.cell.cell_json === result.cell.cell_json && result.replay.cell.sha256 === result.cell.sha256,
    `the same session makes the same cell document, byte for byte (sha256 ${result.cell.sha256} and ${result.replay.cell.sha256})`);

  // --- rehearsed: the console starts the rehearsal cell on the new product's revision, the run is followed
  //     to its end, then back to the plan ---
  const tRehearse = Date.now();
  await again.click('#planner-rehearse');
  await again.waitForFunction(() => !document.querySelector('#rehearsal').hidden
    || /Not rehearsed/.test(document.querySelector('#planner-notice')?.textContent || ''), null, { timeout: 240000, polling: 500 });
  check(await again.locator('#rehearsal').isVisible(), `the rehearsal was sent once the rehearsal cell was up (${await again.locator('#planner-notice').innerText()})`);
  await again.waitForFunction(() => window.rigger.planner.rehearsal.ended(), null, { timeout: 360000, polling: 500 });
  result.rehearsal = { state: await again.evaluate(() => window.rigger.planner.rehearsal.state()), task_id: await again.evaluate(() => window.rigger.planner.rehearsal.taskId) };
  result.rehearsal.cell = (await call('/api/rehearsal/cell')).json;
  result.timings_ms.rehearsal = Date.now() - tRehearse;
  check(result.rehearsal.state === 'SUCCEEDED', `the rehearsal ended ${result.rehearsal.state}`);
  await again.click('#rehearsal-back');

  // --- published: the console's cell runs it, once it is the cell in physics (CELL_EXECUTORS: the test
  //     brings it up after the rehearsal cell stopped) ---
  const tCell = Date.now();
  await waitForExecutors(env('CELL_EXECUTORS').split(','), 300000);
  result.timings_ms.cell_up = Date.now() - tCell;
  await again.click('#planner-publish');
  await again.waitForFunction(() => document.querySelector('#confirm[open]') || document.querySelector('#planner-notice.error'), null, { timeout: 60000 });
  check(await again.locator('#confirm[open]').count() === 1, `Publish asks for confirmation (${await again.locator('#planner-notice').innerText()})`);
  await again.click('#confirm-yes');
  await again.waitForFunction(() => /Published /.test(document.body.innerText), null, { timeout: 60000 });
  result.published = JSON.parse(result.exported).task_id;
  result.timings_ms.total = Date.now() - t0;
} catch (e) {
  if (shown && !shown.isClosed()) {
    await shown.screenshot({ path: path.join(ART, 'new-product-failed.png'), fullPage: true }).catch(() => {});
    result.failed_at = await shown.evaluate(() => ({ selected: window.rigger.planner.state.selected,
      drawn: window.rigger.planner.drawnRevision, form: document.querySelector('.pform')?.innerText.slice(0, 2000) })).catch((x) => String(x));
  }
  throw e;
} finally {
  await closeBrowser(browser, result);
}
