fn main() {
    for f in std::fs::read_dir("../examples/mechanisms").unwrap() {
        let p = f.unwrap().path();
        let text = std::fs::read_to_string(&p).unwrap();
        let Ok(c) = pkm_dsl::compile(&text) else {
            println!("{}: compile error", p.display());
            continue;
        };
        let a = &c.analysis;
        if !a.mechanism.planar {
            continue;
        }
        let fp = pkm_dsl::planner::forward_plan(a);
        let ip = pkm_dsl::planner::inverse_plan(a);
        println!(
            "{}: fk {} ik {}",
            p.display(),
            match &fp {
                Ok(p) => format!("ok {} steps {} br", p.steps.len(), p.branches),
                Err(e) => format!("ERR {:?}", e.0.iter().map(|d| d.message.clone()).collect::<Vec<_>>()),
            },
            match &ip {
                Ok(p) => format!("ok {} steps {} br", p.steps.len(), p.branches),
                Err(e) => format!("ERR {:?}", e.0.iter().map(|d| d.message.clone()).collect::<Vec<_>>()),
            }
        );
    }
}
