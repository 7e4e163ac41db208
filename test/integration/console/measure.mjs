// Measurements of what the console's pages render, for e2e.mjs: the highlighted hole on the operator
// station's canvas (found in a screenshot's pixels, not asked of the page) and the plotted series.

// The highlight's colour (view3d.js GREEN, drawn unlit by MeshBasicMaterial): pixels within this distance
// per channel count as the highlight; antialiased edges and the label's darker green (#128a3e) do not.
const GREEN = [0x19, 0xc1, 0x5a];
const GREEN_TOLERANCE = 24;

/// Where `position` (world, metres) lands on a canvas of `width` x `height` CSS pixels under the
/// column-major view-projection `vp`: [x, y] from the canvas's top-left corner.
export function project(vp, width, height, [x, y, z]) {
  const clip = [0, 1, 2, 3].map((r) => vp[r] * x + vp[4 + r] * y + vp[8 + r] * z + vp[12 + r]);
  const ndc = [clip[0] / clip[3], clip[1] / clip[3]];
  return [(ndc[0] + 1) / 2 * width, (1 - ndc[1]) / 2 * height];
}

/// The centroid (CSS pixels from the canvas's top-left corner) and count of the highlight-coloured pixels
/// in a screenshot of the canvas `selector` on `page`. The PNG is decoded in the browser's own image
/// decoder; the page's scripts are not asked where anything is.
export async function highlightOnScreen(page, selector) {
  const png = await page.locator(selector).screenshot();
  return page.evaluate(async ([b64, green, tol]) => {
    const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
    const image = await createImageBitmap(new Blob([bytes], { type: 'image/png' }));
    const canvas = new OffscreenCanvas(image.width, image.height);
    const g = canvas.getContext('2d');
    g.drawImage(image, 0, 0);
    const { data } = g.getImageData(0, 0, image.width, image.height);
    let n = 0, sx = 0, sy = 0;
    for (let i = 0; i < data.length; i += 4) {
      if (Math.abs(data[i] - green[0]) > tol || Math.abs(data[i + 1] - green[1]) > tol || Math.abs(data[i + 2] - green[2]) > tol) continue;
      const p = i / 4;
      sx += (p % image.width) + 0.5;
      sy += Math.floor(p / image.width) + 0.5;
      n++;
    }
    return { pixels: n, at: n ? [sx / n, sy / n] : null, size: [image.width, image.height] };
  }, [png.toString('base64'), GREEN, GREEN_TOLERANCE]);
}

/// The samples the plots page draws for the series labelled `label`: [[t (s, epoch), value], ...],
/// the gaps (null) left out.
export async function plotted(page, label, where = 'plots') {
  const s = await page.evaluate(([w, l]) => (w === 'replay' ? window.rigger.replay.plots : window.rigger.plots).series(l), [where, label]);
  if (!s) return [];
  return s.t.map((t, i) => [t, s.values[i]]).filter(([, v]) => v !== null && v !== undefined);
}
