// The console on the generated cell (run by generated_cell_browser_test.cpp, which starts the world
// model and the CAD service on it, scripted executors and the console, and writes a screw prompt naming
// flange/h2): headless Debian chromium through playwright-core. The Planner draws the cell's six objects
// from their STEP models, a click on a part fills Localize's object; the operator station draws the
// flange and highlights h2 where its CAD position projects; the programmer applies a revision moving a
// loose part from the Tasks page (viewer and operator refused), and the pages draw it at its new place.
// Any failed check ends the script with exit code 1.
import fs from 'node:fs';
import path from 'node:path';

import { consoleRequest, env } from '../browser.mjs';
import { highlightOnScreen, project } from '../console/measure.mjs';
import { ART, URL_, TOKEN, call, check, closeBrowser, launchBrowser, openPlanner, waitForSkills } from './harness.mjs';

const FLANGE_HOLES = JSON.parse(env('FLANGE_HOLES'));
const MOVED_CELL = env('MOVED_CELL');
const MOVED = env('MOVED_PART');
const MOVE_X = Number(env('MOVE_X_M'));
const tokens = { operator: env('TOKEN_OPERATOR'), viewer: env('TOKEN_VIEWER') };
// The objects the generated cell holds; part_c is given as a box (`shape: box`), the others by STEP
// (the table's is a box too, but a STEP solid: CAD's faces and the model's sha256, not the fallback).
const STEP_OBJECTS = ['fixture_table', 'bracket', 'flange', 'part_a', 'part_b'];
const BOX_OBJECTS = ['part_c'];
// The operator station's highlight (pin, ring, frame) sits a few mm above the hole's entry: its centroid
// is a few px off the entry's projection (console/e2e.mjs measured 3.1 px on the shipped cell).
const HOLE_TOLERANCE_PX = 5;
// The 3D cell's origin marker is a sphere drawn at the point itself.
const CELL_TOLERANCE_PX = 2;
const result = {};

await waitForSkills(['Localize']);
const browser = await launchBrowser();
try {
  // --- the Planner: six objects, each from its STEP model (or the box the file gives) ---
  const planner = await openPlanner(browser);
  const drawn = await planner.evaluate(() => Object.fromEntries([...window.rigger.planner.view.parts]
    .map(([id, p]) => [id, { box: !!p.box, sha256: p.sha256, meshes: p.meshes.length, triangles: p.meshes.reduce((n, m) => n + (m.mesh.geometry.index?.count ?? m.mesh.geometry.attributes.position.count) / 3, 0) }])));
  result.planner_parts = drawn;
  check(Object.keys(drawn).length === 6, `the Planner draws the six objects (${Object.keys(drawn)})`);
  for (const id of STEP_OBJECTS) check(drawn[id] && !drawn[id].box && /^[0-9a-f]{64}$/.test(drawn[id].sha256) && drawn[id].triangles >= 12, `${id} is drawn from its STEP model's tessellation ${JSON.stringify(drawn[id])}`);
  for (const id of BOX_OBJECTS) check(drawn[id]?.box, `${id}, a box in the cell file, is drawn as its box`);
  const listed = await planner.$$eval('#planner-parts input[data-part]', (xs) => xs.map((x) => x.dataset.part));
  check([...STEP_OBJECTS, ...BOX_OBJECTS].every((id) => listed.includes(id)), `the part list names each object (${listed})`);

  // --- Localize's object, by a click on part_b in the 3D view ---
  await planner.selectOption('#planner-add-kind', 'skill:Localize');
  await planner.click('#planner-add');
  await planner.click('#planner-parts button[data-frame="part_b"]');
  await planner.click('button[data-pick-object="object"]');
  await planner.evaluate(() => window.scrollTo(0, 0));
  const at = await planner.evaluate((id) => {
    const v = window.rigger.planner.view;
    v.render();
    const m = v.parts.get(id).meshes[0].mesh;
    m.geometry.computeBoundingBox();
    const c = m.geometry.boundingBox.getCenter(m.position.clone()).applyMatrix4(m.matrixWorld).project(v.camera);
    const r = v.renderer.domElement.getBoundingClientRect();
    const x = r.left + (c.x + 1) / 2 * r.width, y = r.top + (1 - c.y) / 2 * r.height;
    return { x, y, under: v.pickAt(x, y)?.entity };
  }, 'part_b');
  check(at.under === 'part_b', `part_b's centre is on screen, in front (${JSON.stringify(at)})`);
  await planner.mouse.click(at.x, at.y);
  const chosen = await planner.$eval('select[data-object-param="object"]', (s) => s.value);
  check(chosen === 'part_b', `a click on part_b filled Localize's object (${chosen})`);
  result.clicked_object = { at, chosen };
  await planner.screenshot({ path: path.join(ART, 'generated-planner.png'), fullPage: true });

  // --- the operator station: the flange drawn, h2 highlighted where its CAD position projects ---
  // Each tab keeps its own login (sessionStorage): the operator's here, the programmer's in the others.
  const op = await browser.context.newPage();
  await op.goto(`${URL_}/?token=${tokens.operator}#/operator`);
  const seen = await (await op.waitForFunction(() => {
    const o = window.rigger?.operator, v = window.rigger?.view3d;
    if (!o || o.prompt_id !== 'p-flange-h2' || !v || v.entity !== 'flange' || v.highlighted !== 'h2' || !v.source || v.source === 'none') return false;
    return { hole: o.hole, view: { ...v } };
  }, null, { timeout: 60000, polling: 200 })).jsonValue();
  check(seen.view.entity === 'flange', `the station draws the flange, the part owning flange/h2 (${seen.view.entity})`);
  check(seen.view.source === 'cad', `the station draws the flange's CAD model (source ${seen.view.source}, ${seen.view.cad_error || ''})`);
  check(JSON.stringify(seen.view.holes) === JSON.stringify(Object.keys(FLANGE_HOLES)), `the station loaded the flange's holes, not the target's (${seen.view.holes})`);
  const expected = project(seen.view.camera.view_projection, seen.view.camera.width, seen.view.camera.height, FLANGE_HOLES.h2);
  const onScreen = await highlightOnScreen(op, '.op .view canvas');
  check(onScreen.at, `the highlight of h2 is on screen (${onScreen.pixels} pixels)`);
  const holeDistance = Math.hypot(onScreen.at[0] - expected[0], onScreen.at[1] - expected[1]);
  result.flange_h2 = { expected_px: expected, seen_px: onScreen.at, pixels: onScreen.pixels, distance_px: holeDistance, page_hole_m: seen.view.hole_m, cad_hole_m: FLANGE_HOLES.h2 };
  check(holeDistance <= HOLE_TOLERANCE_PX, `h2's highlight is ${holeDistance.toFixed(1)} px from its CAD position's projection`);
  await op.screenshot({ path: path.join(ART, 'generated-operator-h2.png') });

  // --- a cell revision: refused to a viewer and an operator, applied by the programmer in two steps ---
  const moved = JSON.parse(fs.readFileSync(MOVED_CELL, 'utf8'));
  for (const [who, token] of Object.entries(tokens)) {
    const r = await consoleRequest(URL_, '/api/cell/revisions', { token, method: 'POST', body: { cell: moved, comment: 'not mine' } });
    check(r.status === 403, `${who} submitting a cell revision -> 403 (${r.status} ${JSON.stringify(r.json)})`);
  }
  const before = (await call(`/api/world/entity/${MOVED}`)).json.pose.position_m;
  const history0 = (await call('/api/cell/history')).json;
  const tasks = await browser.context.newPage();
  await tasks.goto(`${URL_}/?token=${TOKEN}#/tasks`);
  await tasks.waitForFunction(() => window.rigger?.ready === true, null, { timeout: 30000 });
  await tasks.click('summary:text("3D cell")');
  await tasks.waitForFunction(() => window.rigger.cell3d?.loaded === true, null, { timeout: 60000 });
  await tasks.click('summary:text("Cell revisions")');
  // The cell panel says how each camera stands: this cell's was never calibrated.
  await tasks.waitForSelector('ul.calibrations li[data-camera]', { timeout: 30000 });
  const calibration = await tasks.locator('ul.calibrations li[data-camera]').first().innerText();
  check(/^Camera \S+: as drawn \(no calibration recorded\)$/.test(calibration), `the cell panel says the camera is as drawn: ${calibration}`);
  result.calibration = calibration;
  await tasks.setInputFiles('input[type=file][aria-label="Cell file (JSON)"]', MOVED_CELL);
  await tasks.fill('input[aria-label="Comment on the revision"]', `move ${MOVED}`);
  await tasks.click('button:text("Apply…")');
  await tasks.waitForSelector('dialog[open]');
  const dialog = await tasks.locator('dialog[open]').innerText();
  check(dialog.includes(`moved ${MOVED} ${(MOVE_X * 1000).toFixed(0)} mm`), `the dry run says what would change: ${dialog}`);
  await tasks.click('#confirm-yes');
  const revision = history0.cell_revision + 1;
  await tasks.waitForSelector(`table.revisions tr[data-revision="${revision}"]`, { timeout: 30000 });
  const row = await tasks.locator(`table.revisions tr[data-revision="${revision}"]`).innerText();
  check(row.includes('ada') && row.includes(`move ${MOVED}`), `the history shows revision ${revision}, who and why: ${row}`);
  result.revision = { revision, row, dialog };

  // The world model's pose moved by the distance (the test asks it over DDS too).
  const after = (await call(`/api/world/entity/${MOVED}`)).json.pose.position_m;
  const movedBy = after.map((v, i) => v - before[i]);
  check(Math.abs(movedBy[0] - MOVE_X) < 1e-6 && Math.abs(movedBy[1]) < 1e-6 && Math.abs(movedBy[2]) < 1e-6, `the world model has ${MOVED} moved by ${movedBy}`);

  // The 3D cell draws it there: its pose within 1 mm, its origin marker within a few px of the projection.
  await tasks.waitForFunction(([id, p]) => {
    const q = window.rigger.cell3d.picture.objects?.[id]?.position_m;
    return window.rigger.cell3d.revision !== null && q && Math.hypot(q[0] - p[0], q[1] - p[1], q[2] - p[2]) <= 0.001;
  }, [MOVED, after], { timeout: 30000 });
  await tasks.click(`.cell3d button[data-frame="${MOVED}"]`);
  await tasks.evaluate(() => new Promise((ok) => requestAnimationFrame(() => requestAnimationFrame(ok))));
  const cam = await tasks.evaluate(() => window.rigger.cell3d.camera);
  const cellExpected = project(cam.view_projection, cam.width, cam.height, after);
  const marker = await highlightOnScreen(tasks, '.cell3d .pview canvas');
  check(marker.at, `the 3D cell marks ${MOVED}'s origin (${marker.pixels} pixels)`);
  const cellDistance = Math.hypot(marker.at[0] - cellExpected[0], marker.at[1] - cellExpected[1]);
  result.cell3d = { expected_px: cellExpected, seen_px: marker.at, distance_px: cellDistance };
  check(cellDistance <= CELL_TOLERANCE_PX, `the 3D cell draws ${MOVED}'s origin ${cellDistance.toFixed(2)} px from its new pose's projection`);
  await tasks.screenshot({ path: path.join(ART, 'generated-tasks-revision.png'), fullPage: true });

  // The Planner reloads its parts on the revision: the part's frame within 1 mm of the new pose.
  await planner.waitForFunction(([id, p]) => {
    const part = window.rigger.planner.view.parts.get(id);
    if (!part) return false;
    part.group.updateMatrixWorld(true);
    const e = part.group.matrixWorld.elements;
    return Math.hypot(e[12] - p[0], e[13] - p[1], e[14] - p[2]) <= 0.001;
  }, [MOVED, after], { timeout: 30000 });
  result.planner_after = await planner.evaluate((id) => {
    const e = window.rigger.planner.view.parts.get(id).group.matrixWorld.elements;
    return { position_m: [e[12], e[13], e[14]], parts: [...window.rigger.planner.view.parts.keys()] };
  }, MOVED);
  result.planner_after.distance_m = Math.hypot(...result.planner_after.position_m.map((v, i) => v - after[i]));
  check(result.planner_after.parts.length === 6, `the Planner still draws the six objects (${result.planner_after.parts})`);
  console.log(`ok: ${MOVED} moved ${(movedBy[0] * 1000).toFixed(1)} mm; h2 ${holeDistance.toFixed(1)} px; 3D cell ${cellDistance.toFixed(2)} px; planner ${(result.planner_after.distance_m * 1000).toFixed(3)} mm`);
} finally {
  await closeBrowser(browser, result);
}
