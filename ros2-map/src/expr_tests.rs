//! The parser of map expressions: precedence, places, the functions and
//! indexes, the hints for other languages' operators, and its bounds.

use super::*;

fn call(text: &str) -> (Func, Vec<Expr>) {
    match parse(text) {
        Ok(Expr::Call(f, args, r)) => {
            assert_eq!(r, (0, text.len()), "{text}");
            (f, args)
        }
        other => panic!("{text}: {other:?}"),
    }
}

#[test]
fn precedence_and_places() {
    let e = parse("min(ranges) < 0.5 and not x.y[2] == 'a'").unwrap();
    let Expr::Binary(BinOp::And, l, r, range) = e else { panic!("{e:?}") };
    assert_eq!(range, (0, 39));
    assert!(matches!(*l, Expr::Binary(BinOp::Lt, _, _, (0, 17))));
    assert!(matches!(*r, Expr::Not(_, _)));
    assert!(matches!(parse("1 + 2 * 3").unwrap(), Expr::Binary(BinOp::Add, _, _, _)));
}

#[test]
fn errors_have_places() {
    for (text, at) in [("", 0), ("a.", 2), ("a[]", 2), ("1 +", 3), ("foo(x)", 0), ("a b", 2), ("'x", 0), ("é", 0)] {
        let e = parse(text).unwrap_err();
        assert_eq!(e.range.0, at, "{text:?}: {e:?}");
        assert!(e.range.1 <= text.len());
    }
}

#[test]
fn functions_over_elements() {
    let (f, args) = call("any(status, level >= 2)");
    assert_eq!(f, Func::Any);
    assert!(matches!(&args[0], Expr::Path(s, (4, 10)) if s.len() == 1));
    assert!(matches!(&args[1], Expr::Binary(BinOp::Ge, _, _, (12, 22))));
    assert_eq!(call("all(status, level == 0)").0, Func::All);
    assert_eq!(call("count(ranges, it < 0.5)").0, Func::Count);
    assert_eq!(call("max(status, level)").0, Func::Max);
    assert_eq!(call("min(status, level)").0, Func::Min);
    assert_eq!(call("mean(status, level)").0, Func::Mean);
    assert_eq!(call("index(name, 'elbow')").0, Func::Index);
    assert_eq!(call("hypot(x, y)").0, Func::Hypot);
    for (text, f) in [("abs(x)", Func::Abs), ("sqrt(x)", Func::Sqrt), ("norm(v)", Func::Norm)] {
        assert_eq!(call(text).0, f);
    }
    for (text, f) in [("yaw(q)", Func::Yaw), ("pitch(q)", Func::Pitch), ("roll(q)", Func::Roll)] {
        assert_eq!(call(text).0, f);
    }
    // One argument: the reducers of before.
    assert!(matches!(parse("max(ranges)").unwrap(), Expr::Reduce(Reducer::Max, _, (0, 11))));
    let (_, args) = call("any(status, any(values, key == 'fault'))");
    assert!(matches!(&args[1], Expr::Call(Func::Any, a, (12, 39)) if a.len() == 2));
}

#[test]
fn members_and_indexes_of_any_value() {
    let e = parse("find(status, name == 'motor').level").unwrap();
    let Expr::Member(base, name, r, whole) = e else { panic!("{e:?}") };
    assert!(matches!(*base, Expr::Call(Func::Find, _, (0, 29))));
    assert_eq!((name.as_str(), r, whole), ("level", (30, 35), (0, 35)));

    let e = parse("position[index(name, 'elbow')]").unwrap();
    let Expr::At(base, index, whole) = e else { panic!("{e:?}") };
    assert!(matches!(*base, Expr::Path(_, (0, 8))));
    assert!(matches!(*index, Expr::Call(Func::Index, _, (9, 29))));
    assert_eq!(whole, (0, 30));

    let e = parse("status_list[-1].goal_info.stamp").unwrap();
    let Expr::Member(base, _, _, (0, 31)) = e else { panic!("{e:?}") };
    let Expr::Member(base, _, _, (0, 25)) = *base else { panic!("{base:?}") };
    assert!(matches!(*base, Expr::At(_, ref i, (0, 15)) if matches!(**i, Expr::Neg(..))));

    // A whole number written as such stays a plain path.
    let e = parse("status[0].values[12].key").unwrap();
    let Expr::Path(steps, (0, 24)) = e else { panic!("{e:?}") };
    assert_eq!(steps[1], Step::Index(0, (6, 9)));
    assert_eq!(steps[3], Step::Index(12, (16, 20)));
    // Anything else is an index expression, typed later.
    for text in ["a[0.0]", "a['x']", "a[true]", "a[i + 1]", "a[1e2]"] {
        assert!(matches!(parse(text).unwrap(), Expr::At(..)), "{text}");
    }
    assert!(matches!(parse("(v).x").unwrap(), Expr::Member(..)));
}

#[test]
fn calls_with_the_wrong_arguments() {
    let e = parse("any(status)").unwrap_err();
    assert_eq!((e.message.as_str(), e.range), ("`any` takes 2 arguments, found 1", (0, 11)));
    assert!(e.help.unwrap().contains("any(status, level >= 2)"));
    assert_eq!(parse("max(a, b, c)").unwrap_err().message, "`max` takes 1 or 2 arguments, found 3");
    assert!(parse("len(a, b)").unwrap_err().help.unwrap().contains("count(array, condition)"));
    assert_eq!(parse("abs()").unwrap_err().message, "`abs` takes 1 argument, found 0");
    let e = parse("any(status level)").unwrap_err();
    assert_eq!((e.message.as_str(), e.range), ("expected `,` or `)` in `any(…)`", (11, 16)));
    let e = parse("a, b").unwrap_err();
    assert_eq!(e.range, (1, 2));
}

#[test]
fn an_unknown_function_names_the_closest() {
    let e = parse("cout(status, level > 1)").unwrap_err();
    assert_eq!((e.message.as_str(), e.range), ("`cout` is not a function", (0, 4)));
    assert!(e.help.unwrap().starts_with("did you mean `count`?"));
    let e = parse("frobnicate(x)").unwrap_err();
    assert!(e.help.as_deref().unwrap_or("").starts_with("the functions are min, max"), "{e:?}");
}

#[test]
fn operators_of_other_languages_name_ours() {
    for (text, at, fix) in [
        ("level = 2", (6, 7), "write `==`"),
        ("a && b", (2, 4), "write `and`"),
        ("a & b", (2, 3), "write `and`"),
        ("a || b", (2, 4), "write `or`"),
        ("!ok", (0, 1), "write `not`"),
        ("x =< 1", (2, 4), "write `<=`"),
        ("x => 1", (2, 4), "write `>=`"),
        ("x <> 1", (2, 4), "write `!=`"),
    ] {
        let e = parse(text).unwrap_err();
        assert_eq!((e.range, e.label.as_deref()), (at, Some(fix)), "{text}: {e:?}");
        assert!(e.help.is_some(), "{text}");
    }
    assert_eq!(parse("a && b").unwrap_err().message, "`&&` is written `and` in situ");
    assert!(parse("a != b").is_ok());
}

#[test]
fn chained_comparisons_are_refused_with_the_fix() {
    let e = parse("0 < x < 5").unwrap_err();
    assert_eq!(e.range, (6, 9));
    assert_eq!(e.help.as_deref(), Some("write `0 < x and x < 5`"));
    let e = parse("a == b == c").unwrap_err();
    assert_eq!(e.help.as_deref(), Some("write `a == b and b == c`"));
}

#[test]
fn an_unclosed_string_says_which_quote() {
    let e = parse("name == \"motor").unwrap_err();
    assert_eq!(e.range, (8, 14));
    assert!(e.help.unwrap().contains("single quotes"));
}

#[test]
fn depth_is_bounded() {
    let deep = format!("{}1{}", "(".repeat(200), ")".repeat(200));
    assert!(parse(&deep).unwrap_err().message.contains("nested"));
    assert!(parse(&"not ".repeat(500)).is_err());
    assert!(parse(&"-".repeat(500)).is_err());
    assert!(parse(&"x".repeat(MAX_LEN + 1)).is_err());
    let chain = vec!["x"; 2000].join("+");
    assert!(parse(&chain).unwrap_err().message.contains("tokens"));
    assert!(parse(&vec!["x"; 256].join("+")).is_ok());
    let calls = format!("{}x{}", "abs(".repeat(100), ")".repeat(100));
    assert!(parse(&calls).unwrap_err().message.contains("nested"));
    let scopes = format!("{}x{}", "any(a, ".repeat(40), ")".repeat(40));
    assert!(parse(&scopes).unwrap_err().message.contains("nested"));
    let indexes = format!("a{}", "[a".repeat(100) + &"]".repeat(100));
    assert!(parse(&indexes).unwrap_err().message.contains("nested"));
    // A long postfix chain is bounded by the tokens.
    assert!(parse(&format!("a{}", "[-1]".repeat(200))).unwrap_err().message.contains("tokens"));
    assert!(parse(&format!("a{}", "[-1]".repeat(100))).is_ok());
}
