namespace capsflow::shell {}
