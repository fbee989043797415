//! The parser: every form of the language, and errors with their lines.

use super::*;

fn msg(text: &str) -> Result<MsgDef, IdlError> {
    parse_file("X.msg", "robot", "X", Kind::Msg, text).map(|mut v| v.remove(0))
}

fn ty(base: Base, array: Array) -> TypeRef {
    TypeRef { base, array }
}

#[test]
fn fields_of_every_form() {
    let d = msg("# a comment\n\
                 bool ok  # trailing comment\n\
                 byte b\nchar c\nint8 i8\nuint64 u64\nfloat32 f\nfloat64 g\n\
                 string s\nwstring w\nstring<=10 short\n\
                 Part part\nstd_msgs/Header header\ngeometry_msgs/msg/Pose pose\n\
                 float64[] xs\nint32[3] fixed\nPart[<=4] bounded\nstring<=5[<=2] names\n\
                 int32 with_default 42\nstring greeting \"hi # there\"  # a comment\n")
    .unwrap();
    let names: Vec<&str> = d.fields.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "ok",
            "b",
            "c",
            "i8",
            "u64",
            "f",
            "g",
            "s",
            "w",
            "short",
            "part",
            "header",
            "pose",
            "xs",
            "fixed",
            "bounded",
            "names",
            "with_default",
            "greeting"
        ]
    );
    assert_eq!(d.name, "robot/msg/X");
    assert_eq!(d.fields[0].line, 2);
    assert_eq!(d.field("short").unwrap().ty, ty(Base::Prim(Prim::String(Some(10))), Array::Not));
    assert_eq!(d.field("part").unwrap().ty, ty(Base::Msg("robot/msg/Part".into()), Array::Not));
    assert_eq!(d.field("header").unwrap().ty, ty(Base::Msg("std_msgs/msg/Header".into()), Array::Not));
    assert_eq!(d.field("pose").unwrap().ty, ty(Base::Msg("geometry_msgs/msg/Pose".into()), Array::Not));
    assert_eq!(d.field("xs").unwrap().ty, ty(Base::Prim(Prim::F64), Array::Unbounded));
    assert_eq!(d.field("fixed").unwrap().ty, ty(Base::Prim(Prim::I32), Array::Fixed(3)));
    assert_eq!(d.field("bounded").unwrap().ty, ty(Base::Msg("robot/msg/Part".into()), Array::Bounded(4)));
    assert_eq!(d.field("names").unwrap().ty, ty(Base::Prim(Prim::String(Some(5))), Array::Bounded(2)));
    assert_eq!(d.field("with_default").unwrap().default.as_deref(), Some("42"));
    assert_eq!(d.field("greeting").unwrap().default.as_deref(), Some("\"hi # there\""));
    assert!(d.constants.is_empty());
}

#[test]
fn constants_of_every_type() {
    let d = msg("uint8 CHARGING=1\nint8 STATUS_UNKNOWN   = -3  # spaced\nint64 BIG = 0x10\n\
                 uint64 HUGE = 18446744073709551615\nfloat64 HALF = 0.5\nbool YES = true\n\
                 string NAME = \"a # b\"\nstring BARE = hello world\nuint8 x\n")
    .unwrap();
    let v = |n: &str| d.constant(n).unwrap().value.clone();
    assert_eq!(v("CHARGING"), ConstValue::Int(1));
    assert_eq!(v("STATUS_UNKNOWN"), ConstValue::Int(-3));
    assert_eq!(v("BIG"), ConstValue::Int(16));
    assert_eq!(v("HUGE"), ConstValue::Float(u64::MAX as f64));
    assert_eq!(v("HALF"), ConstValue::Float(0.5));
    assert_eq!(v("YES"), ConstValue::Bool(true));
    assert_eq!(v("NAME"), ConstValue::Str("a # b".into()));
    assert_eq!(v("BARE"), ConstValue::Str("hello world".into()));
    assert_eq!(d.constant("CHARGING").unwrap().ty, Prim::U8);
    assert_eq!(d.constant("CHARGING").unwrap().line, 1);
    assert_eq!(d.fields.len(), 1);
}

#[test]
fn services_and_actions() {
    let srv = parse_file("S.srv", "robot", "Move", Kind::Srv, "float64 x\n---\nbool ok\n").unwrap();
    let names: Vec<&str> = srv.iter().map(|d| d.name.as_str()).collect();
    assert_eq!(names, ["robot/srv/Move_Request", "robot/srv/Move_Response"]);
    assert_eq!(srv[1].fields[0].line, 3);
    let act =
        parse_file("A.action", "robot", "Grip", Kind::Action, "Part goal\n---\nbool ok\n---\nfloat32 gap\n").unwrap();
    let names: Vec<&str> = act.iter().map(|d| d.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "robot/action/Grip_Goal",
            "robot/action/Grip_Result",
            "robot/action/Grip_Feedback",
            "robot/action/Grip_FeedbackMessage"
        ]
    );
    // A type of the package in an action is its message.
    assert_eq!(act[0].fields[0].ty.base, Base::Msg("robot/msg/Part".into()));
    let fm = &act[3];
    assert_eq!(fm.fields[0].ty.base, Base::Msg("unique_identifier_msgs/msg/UUID".into()));
    assert_eq!(fm.fields[1].ty.base, Base::Msg("robot/action/Grip_Feedback".into()));
    let err = parse_file("A.action", "robot", "Grip", Kind::Action, "bool a\n---\nbool b\n").unwrap_err();
    assert!(err.message.contains("2 `---` separators, this one has 1"), "{err}");
}

#[test]
fn errors_have_lines() {
    let cases = [
        ("bool ok\nfloat65 x\n", 2, "`float65` is not a type"),
        ("bool\n", 1, "has no name"),
        ("int32[0] x\n", 1, "above 0"),
        ("int32[x] x\n", 1, "above 0"),
        ("int32[ x\n", 1, "an array is"),
        ("string<=0 s\n", 1, "bounded string"),
        ("# c\n\nbool Bad\n", 3, "not a field name"),
        ("bool a_\n", 1, "not a field name"),
        ("uint8 low = 1\n", 1, "not a constant name"),
        ("uint8 X = 256\n", 1, "out of the range of uint8"),
        ("int8 X = -129\n", 1, "out of the range of int8"),
        ("uint8 X = 1.5\n", 1, "not an integer"),
        ("bool X = maybe\n", 1, "not a bool"),
        ("float32 X = pi\n", 1, "not a number"),
        ("uint8 X =\n", 1, "no value"),
        ("string X = \"open\n", 1, "not closed"),
        ("Part[] X = 1\n", 1, "primitive type"),
        ("bool a\nbool a\n", 2, "defined twice"),
        ("a/b/c/d x\n", 1, "is not a type"),
        ("Bad-Name x\n", 1, "is not a type"),
    ];
    for (text, line, what) in cases {
        let e = msg(text).unwrap_err();
        assert_eq!(e.line, line, "{text:?}: {e}");
        assert!(e.message.contains(what), "{text:?}: {e}");
        assert!(e.to_string().starts_with(&format!("X.msg:{line}: ")), "{e}");
    }
    let e = parse_file("x.msg", "robot", "x-y", Kind::Msg, "").unwrap_err();
    assert_eq!(e.line, 0);
    let e = parse_file("x.msg", "Robot", "X", Kind::Msg, "").unwrap_err();
    assert!(e.message.contains("package name"), "{e}");
}

#[test]
fn text_is_kept() {
    let d = msg("# doc\nbool ok\n").unwrap();
    assert_eq!(d.text, "# doc\nbool ok\n");
    let srv = parse_file("S.srv", "robot", "S", Kind::Srv, "bool a\n---\nbool b").unwrap();
    assert_eq!(srv[0].text, "bool a\n");
    assert_eq!(srv[1].text, "bool b\n");
}

#[test]
fn never_panics_on_noise() {
    let noise = [
        "",
        "---",
        "=",
        "#",
        " = ",
        "a",
        "a b = c",
        "[",
        "]]",
        "string<=",
        "x[<=]",
        "uint8 X = -",
        "int64 X = 99999999999999999999999999999999999999999",
        "\u{0}\u{ffff}",
        "string<=5 [] x",
    ];
    for a in noise {
        for b in noise {
            let text = format!("{a}\n{b} {a}\n{b}={a}");
            for kind in [Kind::Msg, Kind::Srv, Kind::Action] {
                let _ = parse_file("n", "robot", "N", kind, &text);
            }
        }
    }
}
