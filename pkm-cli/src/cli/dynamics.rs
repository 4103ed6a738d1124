//! `pkm dynamics`: inverse dynamics at given inputs, their rates and
//! accelerations, every branch of the forward plan in its order (as `pkm
//! fk` lists them), each with the actuators' forces and every joint's
//! reaction by Newton–Euler over the ordered SKCs
//! (`pkm_runtime::newton_euler`) and every joint's value, rate and
//! acceleration, or with the reason it has none; as JSON by name, at one
//! state or at every line of a file (read, solved and written one state at
//! a time).

use super::failure::{Failure, Kind};
use super::solve::{angular, given_text, input_values, load, sign_text, Request};
use super::table::{self, Branch, Cell, Column};
use pkm_runtime::newton_euler::inverse_dynamics;
use serde_json::{json, Map, Value};
use std::io::{BufRead, Write};

/// What every state's dynamics reads: the loaded file, its loading, its
/// plan's inputs and SKCs, its length unit's name.
struct Setup {
    l: super::solve::Loaded,
    loading: pkm_runtime::mass_properties::Loading,
    plan: pkm_runtime::plan::Plan,
    inputs: Vec<usize>,
    skcs: Vec<pkm_runtime::newton_euler::SkcParts>,
    unit: &'static str,
}

impl Setup {
    fn new(r: &Request) -> Result<Setup, Failure> {
        let l = load(r)?;
        let a = &l.compiled.analysis;
        let Some(units) = a.mass_and_loads.units else {
            return Err(Failure::input(
                "dynamics needs the file's units and masses: `units { length = mm; mass = kg; }` and a `masses` block giving every moving link a mass or declaring it massless",
            ));
        };
        let loading = pkm_dsl::numeric::loading(a, &l.model, &l.values).map_err(|d| r.parse_failure(d))?;
        let plan = l.compiled.forward().cloned().map_err(|d| r.parse_failure(d))?;
        let inputs = plan.input_joints(&l.model);
        let skcs = pkm_dsl::numeric::skc_parts(a);
        let unit = units.length.symbol();
        Ok(Setup {
            l,
            loading,
            plan,
            inputs,
            skcs,
            unit,
        })
    }

    /// The inputs' values, rates and accelerations as the solver takes them.
    fn given(&self, r: &Request, q: &[f64], rates: &[f64], accels: &[f64]) -> Result<Vec<Vec<f64>>, Failure> {
        let zeros = vec![0.0; self.inputs.len()];
        let mut given = Vec::new();
        for (flag, list) in [("--q", q), ("--rates", rates), ("--accels", accels)] {
            // Rates and accelerations not given are zero: statics.
            let list = if list.is_empty() && flag != "--q" { &zeros } else { list };
            given.push(input_values(r, &self.l.model, &self.inputs, flag, list)?);
        }
        Ok(given)
    }

    fn units(&self, r: &Request) -> Value {
        let unit = self.unit;
        json!({
            "force": "N",
            "torque": format!("N·{unit}"),
            "length": unit,
            "angle": if r.degrees { "deg" } else { "rad" },
            "reactions": "force and moment (about the joint's point) that the joint's first link (`by`) exerts on its second (`on`), base axes",
        })
    }

    /// Every joint's value, rate and acceleration by name (a spherical
    /// joint's three as a list), angles in the request's unit.
    fn motion(&self, r: &Request, values: &[f64], given: &[Vec<f64>]) -> Option<Value> {
        let model = &self.l.model;
        let a = pkm_runtime::velocity::accelerations(model, values, &given[1], &given[2]).ok()?;
        let (offsets, _) = model.value_offsets();
        let by_name = |all: &[f64]| -> Map<String, Value> {
            model
                .joints
                .iter()
                .zip(&offsets)
                .map(|(j, &o)| {
                    let k = if r.degrees && super::solve::angular(j.kind) {
                        180.0 / std::f64::consts::PI
                    } else {
                        1.0
                    };
                    let these: Vec<f64> = all[o..o + j.kind.dof()].iter().map(|x| x * k).collect();
                    let v = if these.len() == 1 {
                        json!(these[0])
                    } else {
                        json!(these)
                    };
                    (j.name.clone(), v)
                })
                .collect()
        };
        Some(json!({
            "values": by_name(values),
            "rates": by_name(&a.velocities.rates),
            "accelerations": by_name(&a.rates),
        }))
    }

    /// Every branch of the plan at the inputs `given` (values, rates,
    /// accelerations), in the plan's order as `pkm fk` lists them: its
    /// answer, or why it has none (no position there, or no dynamics).
    fn branches(&self, r: &Request, given: &[Vec<f64>]) -> Vec<Value> {
        let model = &self.l.model;
        let names: Vec<&str> = self.inputs.iter().map(|&j| model.joints[j].name.as_str()).collect();
        let joint_name = |j: usize| model.joints[j].name.clone();
        pkm_runtime::plan::run_all(model, &self.plan, &given[0])
            .into_iter()
            .map(|(signs, solution)| {
                // As `pkm fk` numbers and writes them.
                let number = table::number_of(&signs);
                let signs = sign_text(&signs);
                let refused = |why: String| json!({ "branch": number, "signs": signs, "ok": false, "reason": why });
                // In the model's layout: a spherical joint's three values.
                let values = match solution {
                    Ok(s) => s.model_values(model),
                    Err(e) => return refused(pkm_runtime::consistency::name_given(e, &names).to_string()),
                };
                match inverse_dynamics(model, &self.loading, &self.skcs, &values, &given[1], &given[2]) {
                    Ok(d) => {
                        let actuators: Map<String, Value> = names
                            .iter()
                            .zip(&d.actuators)
                            .map(|(n, v)| (n.to_string(), json!(v)))
                            .collect();
                        let reactions: Map<String, Value> = model
                            .joints
                            .iter()
                            .zip(&d.joints)
                            .map(|(j, w)| {
                                let [first, second] = j.links.map(|k| model.links[k].clone());
                                (
                                    j.name.clone(),
                                    json!({ "on": second, "by": first, "force": w.force, "moment": w.moment }),
                                )
                            })
                            .collect();
                        json!({
                            "branch": number,
                            "signs": signs,
                            "ok": true,
                            "actuators": actuators,
                            "reactions": reactions,
                            "undetermined": d.undetermined,
                            "conditioning": d.conditioning,
                            "motion": self.motion(r, &values, given),
                        })
                    }
                    Err(e) => refused(e.describe(&joint_name)),
                }
            })
            .collect()
    }
}

/// The failure when no branch has an answer: every distinct reason, in
/// the branches' order.
fn none_answers(branches: &[Value]) -> Option<Failure> {
    if branches.iter().any(|b| b["ok"] == true) {
        return None;
    }
    let mut reasons: Vec<&str> = Vec::new();
    for why in branches.iter().filter_map(|b| b["reason"].as_str()) {
        if !reasons.contains(&why) {
            reasons.push(why);
        }
    }
    let why = if reasons.is_empty() {
        "the plan has no branch".to_string()
    } else {
        reasons.join("; ")
    };
    Some(Failure::new(
        Kind::Unreachable,
        format!("no branch gives the dynamics here: {why}"),
    ))
}

/// `pkm dynamics`: the file loaded and planned once, answered at any state.
pub struct Dynamics<'r> {
    r: &'r Request<'r>,
    s: Setup,
}

impl<'r> Dynamics<'r> {
    /// Loads and plans the file of `r`; fails where it has no units or
    /// masses, or no forward plan.
    pub fn new(r: &'r Request<'r>) -> Result<Dynamics<'r>, Failure> {
        Ok(Dynamics { r, s: Setup::new(r)? })
    }

    /// Every branch's actuator forces and joint reactions at inputs `q`
    /// with rates `rates` and accelerations `accels` (zeros where not
    /// given), and every joint's value, rate and acceleration (`motion`);
    /// a branch without an answer says why. A failure where no branch has
    /// one. JSON (`json`), or a table of the actuators and, under it, each
    /// answered branch's reactions.
    pub fn answer(&self, q: &[f64], rates: &[f64], accels: &[f64], json: bool) -> Result<String, Failure> {
        let (r, s) = (self.r, &self.s);
        let given = s.given(r, q, rates, accels)?;
        let branches = s.branches(r, &given);
        if let Some(f) = none_answers(&branches) {
            return Err(f);
        }
        if json {
            let v = json!({
                "name": s.l.model.name,
                "units": s.units(r),
                "branches": branches,
            });
            return Ok(format!("{v}\n"));
        }
        let names = self.input_names();
        let at = |list: &[f64]| given_text(&names, list);
        let mut title = format!("{}: inverse dynamics at {}", s.l.model.name, at(q));
        for (what, list) in [("rates", rates), ("accelerations", accels)] {
            if !list.is_empty() {
                title += &format!("; {what} {}", at(list));
            }
        }
        let ok = branches.iter().filter(|b| b["ok"] == true).count();
        title += &format!("; {} branches, {ok} with an answer\n\n", branches.len());
        let rows: Vec<Branch> = branches.iter().map(|b| self.row(b)).collect();
        let mut out = title + &table::branch_table(&self.columns_of(), &rows);
        out += &format!(
            "\nReactions: force (N) and moment (N·{}) about the joint's point that `by` exerts on `on`, base axes.\n",
            s.unit
        );
        for (b, row) in branches.iter().zip(&rows) {
            if b["ok"] == true {
                out += &format!("\nbranch {} ({}):\n", row.number, table::signs_word(&row.signs));
                out += &self.reaction_table(b);
            }
        }
        Ok(out)
    }

    fn input_names(&self) -> Vec<&str> {
        let m = &self.s.l.model;
        self.s.inputs.iter().map(|&j| m.joints[j].name.as_str()).collect()
    }

    /// An input's unit ("rad", "deg" or the length's) with `per` appended.
    fn input_unit(&self, j: usize, per: &str) -> String {
        let kind = self.s.l.model.joints[j].kind;
        let unit = if angular(kind) {
            if self.r.degrees {
                "deg"
            } else {
                "rad"
            }
        } else {
            self.s.unit
        };
        format!("{unit}{per}")
    }

    /// The actuators' columns (a torque in N·length for a turning input, a
    /// force in N for a sliding one), then every joint's reaction (CSV only).
    fn columns_of(&self) -> Vec<Column> {
        let m = &self.s.l.model;
        let torque = format!("N·{}", self.s.unit);
        let actuators = self.s.inputs.iter().map(|&j| {
            let unit = if angular(m.joints[j].kind) {
                torque.as_str()
            } else {
                "N"
            };
            Column::new(&m.joints[j].name, unit)
        });
        let reactions = m.joints.iter().flat_map(|j| {
            let force = ["Fx", "Fy", "Fz"].map(|c| Column::new(format!("{}.{c}", j.name), "N").csv_only());
            let moment = ["Mx", "My", "Mz"].map(|c| Column::new(format!("{}.{c}", j.name), torque.as_str()).csv_only());
            force.into_iter().chain(moment)
        });
        actuators.chain(reactions).collect()
    }

    /// A branch's JSON answer as a row of [`Dynamics::columns_of`].
    fn row(&self, b: &Value) -> Branch {
        let number = b["branch"].as_u64().unwrap_or(0) as usize;
        let signs = table::signs_of(number, self.s.plan.branches);
        if b["ok"] != true {
            let why = b["reason"].as_str().unwrap_or("no answer").to_string();
            return Branch {
                number,
                signs,
                values: Err(why),
            };
        }
        let num = |v: &Value| v.as_f64().map_or(Cell::Empty, Cell::Num);
        let mut cells: Vec<Cell> = self.input_names().iter().map(|n| num(&b["actuators"][*n])).collect();
        for j in &self.s.l.model.joints {
            let w = &b["reactions"][&j.name];
            for part in ["force", "moment"] {
                cells.extend((0..3).map(|k| num(&w[part][k])));
            }
        }
        Branch {
            number,
            signs,
            values: Ok(cells),
        }
    }

    /// Every joint's reaction in an answered branch, a row each.
    fn reaction_table(&self, b: &Value) -> String {
        let torque = format!("N·{}", self.s.unit);
        let mut columns = vec![Column::bare("joint"), Column::bare("on"), Column::bare("by")];
        columns.extend(["Fx", "Fy", "Fz"].map(|c| Column::new(c, "N")));
        columns.extend(["Mx", "My", "Mz"].map(|c| Column::new(c, torque.as_str())));
        let num = |v: &Value| v.as_f64().map_or(Cell::Empty, Cell::Num);
        let rows = self
            .s
            .l
            .model
            .joints
            .iter()
            .map(|j| {
                let w = &b["reactions"][&j.name];
                let text = |v: &Value| Cell::Text(v.as_str().unwrap_or("").to_string());
                let mut row = vec![Cell::Text(j.name.clone()), text(&w["on"]), text(&w["by"])];
                for part in ["force", "moment"] {
                    row.extend((0..3).map(|k| num(&w[part][k])));
                }
                row
            })
            .collect();
        table::Table { columns, rows, key: 1 }.render(table::width())
    }
}

impl super::csv::Solver for Dynamics<'_> {
    /// Each input's value, then each one's rate and acceleration
    /// (`R1 rate`, `R1 accel`).
    fn given(&self) -> Vec<Column> {
        let m = &self.s.l.model;
        let name = |j: usize, suffix: &str| format!("{}{suffix}", m.joints[j].name);
        let of = |suffix: &'static str, per: &'static str| {
            self.s
                .inputs
                .iter()
                .map(move |&j| Column::new(name(j, suffix), self.input_unit(j, per)))
        };
        of("", "").chain(of(" rate", "/s")).chain(of(" accel", "/s²")).collect()
    }

    fn columns(&self) -> Vec<Column> {
        self.columns_of()
    }

    fn choices(&self) -> usize {
        self.s.plan.branches
    }

    fn branches(&self, given: &[f64]) -> Result<Vec<Branch>, Failure> {
        let n = self.s.inputs.len();
        let (q, rest) = given.split_at(n);
        let (rates, accels) = rest.split_at(n);
        let given = self.s.given(self.r, q, rates, accels)?;
        Ok(self.s.branches(self.r, &given).iter().map(|b| self.row(b)).collect())
    }
}

/// The longest line `--states` reads (a state is a few numbers).
pub const MAX_STATE_LINE: usize = 64 * 1024;

/// How a `--states` run went.
#[derive(Debug, Clone, Copy, Default)]
pub struct StatesSummary {
    /// States read (lines that are not blank or comments).
    pub states: usize,
    /// States with at least one branch's answer.
    pub answered: usize,
    /// Lines that are not states (too long, not numbers, a wrong count).
    pub malformed: usize,
}

/// One line of a `--states` file as a state: the inputs' values, rates and
/// accelerations (`n` inputs), or why it is not one.
fn state_numbers(line: &str, n: usize) -> Result<Vec<f64>, String> {
    let numbers: Vec<f64> = line
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| e.to_string())?;
    if numbers.is_empty() || !numbers.len().is_multiple_of(n) || numbers.len() > 3 * n {
        return Err(format!(
            "expected {n}, {} or {} numbers (values, rates, accelerations), found {}",
            2 * n,
            3 * n,
            numbers.len()
        ));
    }
    Ok(numbers)
}

/// One line of `reader`, at most [`MAX_STATE_LINE`] bytes kept (the rest
/// of a longer line is read and dropped): `None` at the end, else the
/// line and whether it was longer.
fn next_line(reader: &mut dyn BufRead, line: &mut Vec<u8>) -> std::io::Result<Option<bool>> {
    line.clear();
    let mut long = false;
    loop {
        let (done, used) = {
            let buf = reader.fill_buf()?;
            if buf.is_empty() {
                return Ok((!line.is_empty() || long).then_some(long));
            }
            match buf.iter().position(|&b| b == b'\n') {
                Some(i) => {
                    let room = MAX_STATE_LINE.saturating_sub(line.len()).min(i);
                    long |= i > room;
                    line.extend_from_slice(&buf[..room]);
                    (true, i + 1)
                }
                None => {
                    let room = MAX_STATE_LINE.saturating_sub(line.len()).min(buf.len());
                    long |= buf.len() > room;
                    line.extend_from_slice(&buf[..room]);
                    (false, buf.len())
                }
            }
        };
        reader.consume(used);
        if done {
            return Ok(Some(long));
        }
    }
}

/// [`dynamics`] at every state of the file `path`, one state a line: the
/// inputs' values, then their rates, then their accelerations, separated
/// by commas (rates and accelerations may be left out: zeros); blank lines
/// and lines starting with `#` are skipped. Each state is read, solved and
/// written to `out` before the next is read, so memory stays constant
/// however many there are: `{"name", "units", "states": [...]}`, each
/// state with its `line` and its `branches`, or its `error` (no branch has
/// an answer, or the line is not a state). `pretty`: indented, as the
/// command line prints without `--json`. An error before the first state
/// (the mechanism, the file) is a failure; one while reading after it ends
/// the list, and is returned with what was written.
pub fn dynamics_states(
    r: &Request,
    path: &std::path::Path,
    out: &mut dyn Write,
    pretty: bool,
) -> Result<(StatesSummary, Option<Failure>), Failure> {
    let s = Setup::new(r)?;
    let shown = path.display();
    let file = std::fs::File::open(path).map_err(|e| Failure::new(Kind::Io, format!("cannot read `{shown}`: {e}")))?;
    let mut reader = std::io::BufReader::new(file);
    // A reader that has gone (`… | head`) is not a failure of ours: the
    // states stop there (as `failure::write_out`).
    let gone = std::cell::Cell::new(false);
    let emit = |out: &mut dyn Write, bytes: &[u8]| -> Result<(), Failure> {
        match out.write_all(bytes) {
            Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => {
                gone.set(true);
                Ok(())
            }
            other => other.map_err(|e| Failure::new(Kind::Io, format!("cannot write the output: {e}"))),
        }
    };
    let head = json!({ "name": s.l.model.name, "units": s.units(r) });
    let text = |v: &Value| {
        if pretty {
            serde_json::to_string_pretty(v).unwrap_or_else(|_| v.to_string())
        } else {
            v.to_string()
        }
    };
    // The head's fields, then the states one by one.
    let head_text = text(&head);
    let head_text = head_text.trim_end();
    let head_text = head_text.strip_suffix('}').unwrap_or(head_text).trim_end();
    let (open, separator, close) = if pretty {
        (",\n  \"states\": [\n", ",\n", "\n  ]\n}\n")
    } else {
        (",\"states\":[", ",", "]}\n")
    };
    emit(out, format!("{head_text}{open}").as_bytes())?;
    let n = s.inputs.len();
    let mut summary = StatesSummary::default();
    let mut line = Vec::new();
    let mut number = 0;
    let mut interrupted = None;
    loop {
        let long = match next_line(&mut reader, &mut line) {
            Ok(Some(long)) => long,
            Ok(None) => break,
            Err(e) => {
                interrupted = Some(Failure::new(
                    Kind::Io,
                    format!("cannot read `{shown}` after line {number}: {e}"),
                ));
                break;
            }
        };
        number += 1;
        let text_line = String::from_utf8_lossy(&line);
        let trimmed = text_line.trim();
        if !long && (trimmed.is_empty() || trimmed.starts_with('#')) {
            continue;
        }
        let state = if long {
            Err(format!("{shown}:{number}: longer than {MAX_STATE_LINE} bytes"))
        } else {
            state_numbers(trimmed, n).map_err(|e| format!("{shown}:{number}: {e}"))
        };
        let value = match state {
            Err(why) => {
                summary.malformed += 1;
                json!({ "line": number, "error": why })
            }
            Ok(numbers) => {
                let part = |i: usize| numbers.get(i * n..(i + 1) * n).unwrap_or(&[]);
                let answer = s.given(r, part(0), part(1), part(2)).and_then(|given| {
                    let branches = s.branches(r, &given);
                    none_answers(&branches).map_or(Ok(branches), Err)
                });
                match answer {
                    Ok(branches) => {
                        summary.answered += 1;
                        json!({ "line": number, "branches": branches })
                    }
                    Err(f) => json!({ "line": number, "error": f.message }),
                }
            }
        };
        if summary.states > 0 {
            emit(out, separator.as_bytes())?;
        }
        summary.states += 1;
        let state_text = text(&value);
        if pretty {
            // Indented under "states".
            let indented: Vec<String> = state_text.lines().map(|l| format!("    {l}")).collect();
            emit(out, indented.join("\n").as_bytes())?;
        } else {
            emit(out, state_text.as_bytes())?;
        }
        if gone.get() {
            return Ok((summary, None));
        }
    }
    emit(out, close.as_bytes())?;
    let _ = out.flush();
    Ok((summary, interrupted))
}
