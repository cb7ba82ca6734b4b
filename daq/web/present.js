// How a number and its unit are shown: shared by the operator's page (page.html) and the fleet
// page (fleet.html), embedded in both by the server (daq/src/web/assets.cpp). The service and
// the store write units as a terminal prints them (um, urad, um/m, degC); the pages write the
// signs an engineer reads (µm, µrad, µm/m, °C), from the table the reports use too
// (::daq::unit_signs, daq/src/results/result_rows.cpp), which the server puts in UNIT_SIGNS.
"use strict";
const present = ((signs) => {
  const sign = new Map(signs);
  // A unit alone ("um" -> "µm"); one that is not in the table as it is.
  const unit = (u) => sign.get(String(u ?? "")) ?? String(u ?? "");
  // A sentence of the service's ("stop quality 0.050 urad"): each unit word written as its sign,
  // as units_html does for the reports (a whole word only: "drum" stays "drum"). Longest first.
  const words = signs.map(([ascii]) => ascii.replace(/[.*+?^${}()|[\]\\/]/g, "\\$&")).join("|");
  const inText = words ? new RegExp(`(^|[^A-Za-z0-9])(${words})(?![A-Za-z0-9])`, "g") : null;
  // A number in it that rounds to zero loses its minus ("-0.000 urad" -> "0.000 µrad"; the
  // service's sentences print with a sign, "{:+.3f}").
  const noNegativeZero = (t) => t.replace(/(^|[^0-9A-Za-z_.])-(0(?:\.0+)?)(?![0-9.])/g, "$1$2");
  const text = (t) => noNegativeZero(inText ? String(t ?? "").replace(inText, (_, before, u) => before + sign.get(u)) : String(t ?? ""));
  // A number to d decimals as the terminal and the reports write it (cal::fixed_text,
  // analysis/src/fixed_text.cpp, step for step): rounded half away from zero at the last place
  // by Math.round of v x 10^d, not by the binary value's digits as toFixed alone does (0.0045 to
  // 3 places is "0.005", toFixed's "0.004"); from 2^52 on the product is whole and v is written
  // as it is. "—" when there is none; a value that rounds to zero has no sign ("0.00", never
  // "-0.00": a captured stop at 0 is not below zero).
  const fixed = (v, d) => {
    if (v === null || v === undefined || !Number.isFinite(Number(v))) return "—";
    const x = Number(v), scale = 10 ** d, scaled = x * scale;
    // Math.round takes a tie up (-2.5 to -2): rounded by size, the sign put back (-3).
    let r = Math.abs(scaled) < 2 ** 52 ? Math.sign(scaled) * Math.round(Math.abs(scaled)) / scale : x;
    if (r === 0) r = 0;  // -0 and whatever rounds to zero
    // toFixed writes 1e21 and over as "1e+21": such a value is whole, its digits from BigInt.
    return Math.abs(r) < 1e21 ? r.toFixed(d) : BigInt(r).toString() + (d > 0 ? "." + "0".repeat(d) : "");
  };
  // With its sign: "+1.2", "-0.4", "+0.0".
  const signed = (v, d) => {
    const s = fixed(v, d);
    return s === "—" || s.startsWith("-") ? s : "+" + s;
  };
  return { unit, text, fixed, signed };
})(typeof UNIT_SIGNS === "undefined" ? [] : UNIT_SIGNS);
