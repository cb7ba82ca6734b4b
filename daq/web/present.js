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
  // A number to d decimals, "—" when there is none; a value that rounds to zero has no sign
  // ("0.00", never "-0.00": a captured stop at 0 is not below zero).
  const fixed = (v, d) => {
    if (v === null || v === undefined || !Number.isFinite(Number(v))) return "—";
    const s = Number(v).toFixed(d);
    return /^-0(\.0*)?$/.test(s) ? s.slice(1) : s;
  };
  // With its sign: "+1.2", "-0.4", "+0.0".
  const signed = (v, d) => {
    const s = fixed(v, d);
    return s === "—" || s.startsWith("-") ? s : "+" + s;
  };
  return { unit, text, fixed, signed };
})(typeof UNIT_SIGNS === "undefined" ? [] : UNIT_SIGNS);
